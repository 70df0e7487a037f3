r"""The method library as a table: every shipped tableau and every generated family, with kind,
size, order and source (``tl.list_methods()``, ``tableau-lab list``).

A shipped method's order is the one its file claims (``tableau-lab verify`` checks every claim;
tests/test_library.py verifies the whole library), computed when the file claims none; a family's
order is its published formula in the size (:data:`FAMILY_ORDERS`: [HW96] Table IV.5.13 for the
collocation families, [HNW93] §III.1–III.2 for the multistep ones; tests/test_api.py checks
each against the order analysis), or the order of its smallest member for a family without one.
The whole table takes about 0.3 s (files read, the smallest member of each family built).

>>> import tableau_lab as tl
>>> rows = tl.list_methods()
>>> row = rows["gauss2"]
>>> row.kind, row.size, row.order
('rk', 's = 2', '4')
>>> rows["gauss"].name, rows["gauss"].order, rows["bdf"].size
('gauss:s', '2s', 'k = 1 … 30')
"""
from __future__ import annotations

from dataclasses import dataclass

from ..exact.library import FAMILIES, library_names, library_path
from ..exact.tableau_json import TableauError, load, read
from ..render import markdown as markdown_format
from ..render.model import Document, Paragraph, Plain, Table
from .order import order
from .results import Result

__all__ = ["list_methods", "MethodList", "MethodRow", "FAMILY_ORDERS"]

#: family -> (its order as a formula in the size n, the same as a function of n)
FAMILY_ORDERS = {
    "gauss": ("2s", lambda n: 2 * n),
    "radau_iia": ("2s − 1", lambda n: 2 * n - 1),
    "radau_ia": ("2s − 1", lambda n: 2 * n - 1),
    "lobatto_iiia": ("2s − 2", lambda n: 2 * n - 2),
    "lobatto_iiib": ("2s − 2", lambda n: 2 * n - 2),
    "lobatto_iiic": ("2s − 2", lambda n: 2 * n - 2),
    "lobatto_iiic_star": ("2s − 2", lambda n: 2 * n - 2),
    "sdirk_crouzeix": ("s + 1", lambda n: n + 1),
    "sdirk_alexander": ("s", lambda n: n),
    "bdf": ("k", lambda n: n),
    "adams_bashforth": ("k", lambda n: n),
    "adams_moulton": ("k + 1", lambda n: n + 1),
    "nystrom": ("k", lambda n: n),
    "milne_simpson": ("k + 1 (4 for k = 2)", lambda n: 4 if n == 2 else n + 1),
}
#: a source longer than this is cut in the text table (JSON and ``row.source`` keep all of it)
SOURCE_SHOWN = 60


@dataclass(frozen=True)
class MethodRow:
    """One line of the library: ``name`` is what :func:`tableau_lab.load` takes (``gauss:s`` for a
    family: ``gauss:3``); ``order_from`` is "claim", "computed" or "formula"."""

    name: str
    kind: str
    size: str
    order: str
    source: str
    order_from: str
    family: bool = False


_FOOTNOTE = ("(order: claimed by the file and checked by `tableau-lab verify`; * computed; "
             "families: the published formula; load a family as name:N, e.g. gauss:3)")


@dataclass(frozen=True)
class MethodList(Result):
    """The rows of :func:`list_methods`; ``rows[name]`` finds one (a family by its bare name)."""

    rows: tuple

    def __getitem__(self, name):
        if isinstance(name, int):
            return self.rows[name]
        for r in self.rows:
            if name in (r.name, r.name.split(":")[0]):
                return r
        raise KeyError(name)

    def __iter__(self):
        return iter(self.rows)

    def __len__(self):
        return len(self.rows)

    @property
    def names(self) -> list:
        return [r.name for r in self.rows]

    def _cells(self):
        return [(r.name, r.kind, r.size, r.order + ("*" if r.order_from == "computed" else ""),
                 r.source if len(r.source) <= SOURCE_SHOWN else r.source[:SOURCE_SHOWN - 1] + "…") for r in self.rows]

    @property
    def title(self) -> str:
        files = sum(not r.family for r in self.rows)
        return f"The method library: {files} shipped tableaux, {len(self.rows) - files} families"

    def display(self) -> Document:
        """The title, the table (name, kind, size, order, source) and, in text, what the columns mean."""
        return Document(self.title, (Plain(Paragraph("")), Table(("name", "kind", "size", "order", "source"),
                                                                 tuple(self._cells())),
                                     Plain(Paragraph(_FOOTNOTE))))

    def markdown(self) -> str:
        """The table in Markdown (``tableau-lab list --markdown``; a notebook shows it)."""
        return markdown_format.render(self.display())

    def to_json(self):
        return {"methods": [{"name": r.name, "kind": r.kind, "size": r.size, "order": r.order,
                             "order_from": r.order_from, "source": r.source, "family": r.family} for r in self.rows]}


def _file_row(name: str) -> MethodRow:
    path = library_path(name)
    if path is None:                    # library_names lists shipped files only: a file removed meanwhile
        raise ValueError(f"{name}.json: no longer in the library")
    data = read(path)
    kind = data.get("kind", "?")
    s = len(data.get("A", ()))
    size = f"s = {s}" + (f", r = {len(data.get('V', ()))}" if kind == "glm" else "")
    claimed = (data.get("claims") or {}).get("order")
    if isinstance(claimed, int) and not isinstance(claimed, bool):
        got, where = str(claimed), "claim"
    else:
        got, where = str(int(order(load(name)))), "computed"
    return MethodRow(name, kind, size, got, str(data.get("source", "")), where)


def _family_row(name: str) -> MethodRow:
    build, key, largest, unit = FAMILIES[name]
    letter = "s" if unit == "stages" else "k"
    smallest = None
    for n in range(1, largest + 1):              # the smallest size with an exact construction
        try:
            smallest = build(n)
            break
        except ValueError:
            continue
    size = f"{letter} = {n} … {largest}"
    formula = FAMILY_ORDERS.get(name)
    if formula is not None:
        got, where = formula[0], "formula"
    elif smallest is not None:                   # a family without its formula here: its smallest member's
        got, where = f"{int(order(smallest))} ({letter} = {n})", "computed"
    else:
        raise ValueError(f"family {name}: no member of size 1 … {largest} can be built")
    return MethodRow(f"{name}:{letter}", smallest.kind if smallest is not None else "?", size, got,
                     smallest.source if smallest is not None else "", where, family=True)


def list_methods() -> MethodList:
    """Every method :func:`tableau_lab.load` takes by name: the shipped tableau files and the
    generated families (``name:N``), with kind, size (stages s; values r for GLMs; steps k),
    order and source (module docstring).  Prints as a text table, shows as a Markdown table in
    a notebook, ``to_json()`` for programs; ``tableau-lab list`` prints the same rows.  The
    families and their orders: [HW96] Hairer & Wanner, *Solving ODEs II*, Table IV.5.13 and §IV.6;
    [HNW93] Hairer, Nørsett & Wanner, *Solving ODEs I*, §III.1–III.2; the files: docs/tableau-format.md.

    >>> import tableau_lab as tl
    >>> methods = tl.list_methods()
    >>> "rk4" in methods.names and "bdf:k" in methods.names
    True
    >>> str(methods).splitlines()[2].split()
    ['name', 'kind', 'size', 'order', 'source']
    """
    rows = []
    for name in library_names():
        try:
            rows.append(_file_row(name))
        except (TableauError, ValueError) as exc:          # a shipped file that does not read: said, not hidden
            rows.append(MethodRow(name, "?", "?", "?", f"unreadable: {exc}", "computed"))
    rows += [_family_row(name) for name in FAMILIES]
    return MethodList(tuple(rows))
