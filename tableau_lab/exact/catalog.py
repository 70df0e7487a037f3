r"""``tl.load`` and ``tl.save``: a method from whatever names it, and back to a tableau file.

``load`` takes a method object (returned as it is), a NodePy method (:mod:`interop`), JSON text
(a string starting with ``{``: :func:`tableau_json.loads`), or a name: a tableau file, a shipped
method (``"gauss2"``, ``"rk4"``), a family with its size (``"gauss:3"``, ``"bdf:4"``), all read by
:func:`tableau_json.load` (every error names the file and the one-based entry; a name that is
none of these gets "did you mean …").

>>> import tableau_lab as tl
>>> tl.load("gauss:3").s, tl.load("rk4").name
(3, 'classical Runge–Kutta (RK4)')
>>> tl.load('{"name": "midpoint", "kind": "rk", "A": [["1/2"]], "b": [1]}').c.T
Matrix([[1/2]])
>>> tl.load("RK4")  # doctest: +NORMALIZE_WHITESPACE
Traceback (most recent call last):
...
tableau_lab.exact.tableau_json.TableauError: RK4: no such file, shipped method or family; did you mean rk4?
(tableau-lab list shows them all)
"""
from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from ..files import OutputRefused, guard_output, path_exists
from . import tableau_json
from .balls import BallMethod
from .methods import Method

__all__ = ["load", "load_with_numbers", "save"]


def load(source: Any, **size: int) -> Method | BallMethod:
    r"""The method that ``source`` names (module docstring): a path, a shipped name
    (``tableau-lab list``, ``tl.list_methods()``), ``"family:N"`` or ``load("gauss", s=3)``, JSON
    text, a NodePy ``RungeKuttaMethod``/``LinearMultistepMethod`` with exact coefficients, or a
    method object.  The format is docs/tableau-format.md; the families are those of
    [HW96] Hairer & Wanner, *Solving ODEs II*, Table IV.5.13 (Gauss, Radau, Lobatto) and [HNW93]
    §III.1 (Adams, BDF).

    >>> import tableau_lab as tl
    >>> m = tl.load("bdf:4")
    >>> m.kind, m.r, int(m.order())
    ('glm', 4, 4)
    >>> tl.load(m) is m
    True

    A decimal tableau (``"numbers": "decimal"``, docs/tableau-format.md) comes back as a
    :class:`~tableau_lab.exact.balls.BallMethod`, its decimals balls, for the certified analyses
    (``tl.verify``):

    >>> d = tl.load('{"name": "Heun, 3 digits", "kind": "rk", "numbers": "decimal", '
    ...             '"A": [[0, 0], [1, 0]], "b": ["0.500", "0.500"], "claims": {"order": 2}}')
    >>> d.entry("b", 1).radius, d.entry("A", 2, 1).exact
    (1/2000, 1)
    """
    if isinstance(source, (Method, BallMethod)):
        if size:
            raise TypeError("load(method): a method object has its size already")
        return source
    if isinstance(source, str) and source.lstrip().startswith("{"):
        return tableau_json.loads_any(source)
    if not isinstance(source, (str, os.PathLike)) and (hasattr(source, "A") and hasattr(source, "b")
                                                       or hasattr(source, "alpha") and hasattr(source, "beta")):
        from .interop import from_nodepy
        return from_nodepy(source)
    if not isinstance(source, (str, os.PathLike)):
        raise TypeError(f"load takes a method or its name (a path, a shipped or family name), JSON text or a "
                        f"NodePy method, not {type(source).__name__}")
    return tableau_json.load_any(source, **size)


def load_with_numbers(source: Any, purpose: str) -> Method:
    """:func:`load`, refusing a method with free parameters: ``purpose`` ("a run", "a plot")
    needs numbers (TableauError naming them).

    >>> load_with_numbers("rk4", "a run").name
    'classical Runge–Kutta (RK4)'
    """
    m = load(source)
    if isinstance(m, BallMethod):
        raise tableau_json.TableauError(m.name, f"{purpose} needs an exact tableau; a decimal one "
                                                f"({tableau_json.DECIMAL_KEY}) is only verified (tableau-lab verify)")
    if m.parameters:
        raise tableau_json.TableauError(m.name, f"{purpose} needs numbers for the free parameters "
                                                f"{', '.join(map(str, m.parameters))}; solve for them first "
                                                "(tableau-lab solve)")
    return m


def save(method: Method, path: str | os.PathLike[str], *, overwrite: bool = False) -> Path:
    """Write ``method`` as a JSON tableau file (docs/tableau-format.md) at ``path``, atomically
    (all of it or nothing: :func:`tableau_lab.files.atomic_write_text`); an existing file is
    replaced only with ``overwrite=True``, and never a folder, a device or a link (the guard of
    every output, :func:`tableau_lab.files.guard_output`).  Returns the path.  What is written
    reads back as the same method (``tl.load(path) == method``).

    >>> import tableau_lab as tl, tempfile, os
    >>> path = os.path.join(tempfile.mkdtemp(), "g2.json")
    >>> tl.load(tl.save(tl.load("gauss:2"), path)) == tl.load("gauss:2")
    True
    >>> tl.save(tl.load("rk4"), path)
    Traceback (most recent call last):
    ...
    tableau_lab.files.OutputRefused: ...g2.json: save: a file is there; not replaced (pass overwrite=True to replace it)
    """
    if not isinstance(method, Method):
        raise TypeError(f"save(method, path): the first argument is a method, not {type(method).__name__}")
    target = Path(path)
    if path_exists(target) and target.is_file() and not target.is_symlink() and not overwrite:
        raise OutputRefused(f"{target}: save: a file is there; not replaced (pass overwrite=True to replace it)")
    guard_output(target, what="save")
    tableau_json.save(method, target)
    return target
