"""NodePy's Runge–Kutta methods (nodepy/runge_kutta_method.py: ``loadRKM`` and the families), read
from the installed nodepy, which must be the version of the mirror's commit (checked: the two
copies of runge_kutta_method.py are compared byte for byte).

* exact methods: NodePy builds them from sympy numbers (``Rational``, ``sqrt``), so the objects'
  entries are exact and are written as they are;
* floating-point methods (Tsit5, CMR6, PD8, the downwind SSP methods, SSP33's embedded weights):
  each float is matched to the decimal literal *as written* in the method's block of ``loadRKM``
  (the float is only used to find its literal; the written text is the value); a method given in
  Shu–Osher form (``alpha``, ``beta``) is converted to Butcher form, A = (I − α₀)⁻¹β₀ and
  b = β₁ + α₁A, in arb ball arithmetic from the literals' balls (NodePy's ``shu_osher_to_butcher``),
  giving derived decimals with the file's ``"radius"``.

Claims are what NodePy's text says: the loadRKM docstring line, the method's name and
description (``5(4)``, ``4th-order``, ``third order``, ``SSP 75`` = 7 stages, order 5), and the
family function's docstring.  Usage::

    python -m tools.corpus.nodepy_rk /work/.mirror/ketch+nodepy/repo [OUT]
"""
from __future__ import annotations

import re
import warnings
from pathlib import Path

import sympy as sp
from flint import arb_mat

from .expr import Unsupported, Val
from .writer import Library, Tableau, command_line, show

FILE = "nodepy/runge_kutta_method.py"
LOWSTORAGE = "nodepy/low_storage_rk.py"
FAMILIES = [("SSPRK2", m) for m in range(2, 7)] + [("SSPRK3", m) for m in (4, 9)] \
    + [("SSPIRK1", m) for m in range(1, 7)] + [("SSPIRK2", m) for m in range(1, 7)] \
    + [("SSPIRK3", m) for m in range(2, 7)] + [("extrap", s) for s in range(1, 7)] \
    + [("DC", s) for s in range(0, 6)] + [("DC_pair", s) for s in range(2, 6)] \
    + [("RKC1", m) for m in range(2, 7)] + [("RKC2", m) for m in range(2, 7)]
RATIONAL = re.compile(r"(?<![\w.])(?:(\d+)\s*\*\s*)?one\s*/\s*(\d+)")
WORDS = {"first": 1, "second": 2, "third": 3, "fourth": 4, "fifth": 5, "sixth": 6}
NUMBER = re.compile(r"(?<![\w.])-?(?:\d+\.\d*|\.\d+)(?:[eE][+-]?\d+)?")


def claims_from(text: str) -> dict:
    """Order claims stated in a piece of NodePy's text."""
    m = re.search(r"(\d+)\((\d+)\)", text) or re.search(r"(\d+)th-order and (\d+)th-order pair", text)
    if m:
        return {"order": int(m.group(1)), "embedded_order": int(m.group(2))}
    m = re.search(r"(\d+)(?:st|nd|rd|th)[- ]order", text) \
        or re.search(r"\b(first|second|third|fourth|fifth|sixth)[- ]order", text)
    if m:
        return {"order": int(m.group(1)) if m.group(1).isdigit() else WORDS[m.group(1)]}
    m = re.search(r"\bSSP ?(\d)(\d)\b", text)
    if m:
        return {"order": int(m.group(2))}
    return {}


def floating(x) -> bool:
    return isinstance(x, (float, sp.Float)) or type(x).__name__ in ("float64", "float32")


def exact(x) -> Val:
    if floating(x):
        raise Unsupported("a floating-point entry")
    e = sp.sympify(x) if not isinstance(x, (int,)) else sp.Integer(x)
    if type(x).__module__ == "numpy":
        e = sp.Integer(int(x))
    return Val(exact=e)


class Literals:
    """The decimal literals written in a block of source: a float → the literal it was read from."""

    def __init__(self, block: str) -> None:
        self.by_value: dict = {}
        self.rationals: dict = {}
        for t in NUMBER.findall(block):
            self.by_value.setdefault(float(t), t)        # the float only finds the literal
        for m in RATIONAL.finditer(block):              # k*one/n, one/n: exact entries cast to float
            q = sp.Rational(int(m.group(1) or 1), int(m.group(2)))
            self.rationals.setdefault(float(q), q)

    def val(self, x) -> Val:
        if not floating(x):
            return exact(x)
        if float(x) in self.rationals:
            return Val(exact=self.rationals[float(x)])
        if -float(x) in self.rationals:
            return Val(exact=-self.rationals[-float(x)])
        if float(x) in self.by_value:
            return Val.literal(self.by_value[float(x)])
        if -float(x) in self.by_value:
            return Val.literal(self.by_value[-float(x)]).neg()
        if float(x) == int(x):
            return Val(exact=sp.Integer(int(x)))
        raise Unsupported(f"the float {x!r} is not a literal of the method's source block")


def block_of(text: str, key: str) -> tuple[str, int]:
    """The source block (between ``#====`` lines) that assigns RK['key'], and its first line."""
    pos = text.find(f"RK['{key}']")
    if pos < 0:
        pos = text.find(f"RK[u\"{key}\"]")
    if pos < 0:
        raise Unsupported(f"RK['{key}'] not found in the source")
    start = text.rfind("#====", 0, pos)
    end = text.find("#====", pos)
    return text[start:end if end > 0 else len(text)], text.count("\n", 0, pos) + 1


def shu_osher(alpha, beta, lits: Literals):
    """Butcher A, b from Shu–Osher α, β in arb (NodePy's shu_osher_to_butcher, Gottlieb et al. 2009)."""
    m = len(alpha[0])
    al = [[lits.val(x).as_arb() for x in row] for row in alpha]
    be = [[lits.val(x).as_arb() for x in row] for row in beta]
    X = arb_mat([[(1 if i == j else 0) - al[i][j] for j in range(m)] for i in range(m)])
    A = X.solve(arb_mat([row[:m] for row in be[:m]]))
    b = [be[m][j] + sum((al[m][k] * A[k, j] for k in range(m)), 0 * be[m][j]) for j in range(m)]
    rows = [[Val(ball=A[i, j]) for j in range(m)] for i in range(m)]
    return rows, [Val(ball=v) for v in b]


def float_method(rkm, text: str, key: str):
    block, _ = block_of(text, key)
    lits = Literals(block)
    if getattr(rkm, "alpha", None) is not None and "alpha" in block:
        A, b = shu_osher(rkm.alpha.tolist(), rkm.beta.tolist(), lits)
    else:
        A = [[lits.val(x) for x in row] for row in rkm.A.tolist()]
        b = [lits.val(x) for x in rkm.b.tolist()]
    bhat = [lits.val(x) for x in rkm.bhat.tolist()] if hasattr(rkm, "bhat") else None
    return A, b, bhat


def method(rkm, key: str, text: str, doc: str):
    try:
        A = [[exact(x) for x in row] for row in rkm.A.tolist()]
        b = [exact(x) for x in rkm.b.tolist()]
        bhat = [exact(x) for x in rkm.bhat.tolist()] if hasattr(rkm, "bhat") else None
        how = "exact"
    except Unsupported:
        A, b, bhat = float_method(rkm, text, key)
        how = "decimal literals of loadRKM's block"
    c = None if any(floating(x) for x in rkm.c.tolist()) else [exact(x) for x in rkm.c.tolist()]
    return A, b, c, bhat, how


def docstring_line(text: str, key: str) -> str:
    m = re.search(rf"\* '{re.escape(key)}'?:?[ \t]*([^\n]*)", text)
    return m.group(1) if m else ""


def claims_for(rkm, key: str, text: str, family_doc: str = "") -> tuple[dict, str]:
    for where, t in (("the loadRKM docstring", docstring_line(text, key)), ("the method's name", rkm.name),
                     ("the method's description", getattr(rkm, "info", "") or ""),
                     ("the family function's docstring", family_doc)):
        found = claims_from(t or "")
        if found:
            return found, f"claims read from {where}: {' '.join((t or '').split())[:160]!r}"
    return {}, "NodePy states no order for this method"


def add(lib: Library, rkm, key: str, text: str, line: int, family_doc: str = "", path: str = FILE) -> None:
    where = lib.provenance(path, line)
    try:
        A, b, c, bhat, how = method(rkm, key, text, family_doc)
    except Unsupported as exc:
        lib.skip(key, f"unreadable: {exc}", where)
        return
    claims, note = claims_for(rkm, key, text, family_doc)
    if bhat is None:
        claims.pop("embedded_order", None)
    lib.add(Tableau(name=key, kind="rk", A=A, b=b, c=c, bhat=bhat, claims=claims,
                    notes=[note, f"coefficients: {how} (NodePy {nodepy_version()} object {rkm.name!r})"],
                    source=f"NodePy, {path}, " + (f"loadRKM()['{key}']" if not family_doc else key),
                    provenance=where))


def nodepy_version() -> str:
    import nodepy
    return nodepy.__version__


def extract(git_dir: str, out: Path) -> Library:
    warnings.filterwarnings("ignore")
    import nodepy
    from nodepy import rk
    text = show(git_dir, FILE)
    installed = Path(nodepy.__file__).with_name("runge_kutta_method.py").read_text(encoding="utf-8")
    if installed != text:
        raise SystemExit(f"the installed nodepy's {FILE} differs from the mirror's: install the mirror's commit")
    lib = Library(out, "nodepy", "ketch/nodepy", git_dir)
    for key, rkm in sorted(rk.loadRKM("All").items()):
        if key == "Söderlind43":
            lib.skip(key, "duplicate: the same object as Soderlind43")
            continue
        add(lib, rkm, key, text, block_of(text, key)[1])
    for fam, size in FAMILIES:
        fn = getattr(rk, fam)
        line = text.count("\n", 0, text.find(f"def {fam}(")) + 1
        try:
            rkm = fn(size)
        except Exception as exc:                        # a size NodePy does not build
            lib.skip(f"{fam}({size})", f"NodePy raises {type(exc).__name__}", lib.provenance(FILE, line))
            continue
        if rkm.A.size == 0:
            lib.skip(f"{fam}({size})", "an empty tableau", lib.provenance(FILE, line))
            continue
        add(lib, rkm, f"{fam}({size})", text, line, family_doc=fn.__doc__ or " ")
    return lib


if __name__ == "__main__":
    command_line(extract, "tools.corpus.nodepy_rk")

