r"""A problem's functions as numba source text, for the compiled step loops (:mod:`kernels`,
:mod:`stepcore`): f, the Jacobian, the q- and p-rates of a separable problem, the invariants
and their gradients, in float64 (printed from the symbols with small integer and half-integer
powers as products and square roots) or in double-double (:mod:`ddcode`).  Every function
writes into an argument: ``f_(y, c, out, i)`` (row i of out), ``fq_``/``fp_`` (their entries
of row i only), ``jac_(y, c, out)``, ``inv_(k, y, c, out)`` (out[0]) and
``grad_(k, y, c, out, i)`` (row i).

>>> import sympy as sp
>>> x, y = sp.symbols("x y")
>>> print(function_source("f_", [x, y], [], [y, -sp.sin(x) / x**3]))
@njit(cache=True, error_model='numpy')
def f_(y, c, out):
    out[0] = y[1]
    out[1] = -math.sin(y[0])/(y[0]*y[0]*y[0])
<BLANKLINE>
"""
from __future__ import annotations

import sympy as sp
from sympy.printing.pycode import PythonCodePrinter

__all__ = ["cse_entries", "function_source", "problem_source"]

class _Printer(PythonCodePrinter):
    """Python/numba source with small integer and half-integer powers as products and square
    roots (as a hand-written C loop would have them), ``math.`` functions."""

    def _print_Pow(self, e, rational=False):
        b, x = e.base, e.exp
        if x.is_Integer and 1 <= abs(int(x)) <= 8:
            prod = "(" + "*".join([self.parenthesize(b, 100)] * abs(int(x))) + ")"
            return prod if x > 0 else f"(1.0/{prod})"
        if x.is_Rational and x.q == 2:
            root = f"math.sqrt({self._print(b)})"
            k = abs(int(x.p))
            prod = "(" + ("*".join([root] * k) if k <= 8 else f"{root}**{k}") + ")"
            return prod if x > 0 else f"(1.0/{prod})"
        return super()._print_Pow(e, rational)


def cse_entries(state, params, exprs) -> tuple:
    """The expressions (a list, or a list of rows) with ``state`` → y[i] and ``params`` → c[j],
    common subexpressions taken out: (temporaries [(name, value)], reduced entries, row width
    or None).  The numba printer below and the C reference's printer both start from it."""
    subs = {s: sp.Symbol(f"y[{i}]") for i, s in enumerate(state)}
    subs.update({p: sp.Symbol(f"c[{j}]") for j, p in enumerate(params)})
    rows = exprs if (exprs and isinstance(exprs[0], (list, tuple))) else None
    flat = [e for row in rows for e in row] if rows else list(exprs)
    flat = [sp.sympify(e).xreplace(subs) for e in flat]
    temps, reduced = sp.cse(flat, symbols=sp.numbered_symbols("x"), optimizations="basic")
    return temps, reduced, (len(rows[0]) if rows else None)


def function_source(name, state, params, exprs, at=None, deco=None, row=False) -> str:
    """``def name(y, c, out)``: the expressions (a list, or a list of rows) of the symbols
    ``state`` (→ y[i]) and ``params`` (→ c[j]) written into ``out``; a list goes to the rows
    ``at`` (default 0, 1, …), the other rows of out are left as they are.  ``row``:
    ``def name(y, c, out, i)`` writing a list into row i of a matrix out (no view is made)."""
    temps, reduced, width = cse_entries(state, params, exprs)
    p = _Printer({"fully_qualified_modules": True})
    lines = [(deco or _DECO).rstrip("\n"), f"def {name}(y, c, out, i):" if row else f"def {name}(y, c, out):"]
    lines += [f"    {t} = {p.doprint(v)}" for t, v in temps]
    for k, v in enumerate(reduced):
        where = f"{k // width}, {k % width}" if width else f"{at[k] if at else k}"
        where = f"i, {where}" if row else where
        lines.append(f"    out[{where}] = {p.doprint(v)}")
    return "\n".join(lines) + "\n"


_DECO = "@njit(cache=True, error_model='numpy')\n"
HOT = ("f_", "fq_", "fp_")           # evaluated in every sweep of the stage iteration


def problem_source(problem, invariant_names, dd: bool = False, hot: str | None = None, cold: str | None = None) -> str:
    """f_, jac_, inv_(k, y, c, out) / grad_(k, y, c, out) for the invariants in
    ``invariant_names`` (index k in that order), and for a separable problem fq_ and fp_, of a
    :class:`~.problems.Problem`; in float64, or in double-double (``dd``, :mod:`ddcode`).
    ``hot``: the decorator line of the functions evaluated in the stage iteration (f_, fq_,
    fp_), e.g. one that inlines them into the loop; ``cold``: that of the others."""
    if dd:
        from .ddcode import dd_source

        def source(name, exprs, at=None, row=False):
            return (hot if hot and name in HOT else cold or _DECO) + dd_source(name, (state, params), exprs, at, row)
    else:
        def source(name, exprs, at=None, row=False):
            return function_source(name, state, params, exprs, at, hot if name in HOT else cold, row)
    state, params = list(problem.state), list(problem.parameter_symbols.values())
    f = list(problem.f_expr)
    parts = [source("f_", f, row=True), source("jac_", sp.Matrix(f).jacobian(state).tolist())]
    if problem.separable:
        k = len(problem.q)
        parts += [source("fq_", f[:k], list(range(k)), row=True), source("fp_", f[k:], list(range(k, 2 * k)), row=True)]
    disp_inv, disp_grad = [], []
    for k, name in enumerate(invariant_names):
        invariant = problem.invariants[name]
        parts.append(source(f"inv{k}_", [invariant]))
        parts.append(source(f"grad{k}_", [sp.diff(invariant, x) for x in state], row=True))
        disp_inv.append(f"    if k == {k}:\n        inv{k}_(y, c, out)")
        disp_grad.append(f"    if k == {k}:\n        grad{k}_(y, c, out, i)")
    parts.append(f"{cold or _DECO}def inv_(k, y, c, out):\n" + "\n".join(disp_inv) + "\n    return\n")
    parts.append(f"{cold or _DECO}def grad_(k, y, c, out, i):\n" + "\n".join(disp_grad) + "\n    return\n")
    return "\n\n".join(parts)
