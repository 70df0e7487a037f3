r"""Methods from and to NodePy (D. I. Ketcheson et al., https://github.com/ketch/nodepy), and
from plain Python data.

NodePy is optional (``pip install tableau-lab[nodepy]``).  :func:`from_nodepy` takes a NodePy
Runge–Kutta method whose coefficients are exact (integers, sympy numbers: 41 of the 51 methods
of ``nodepy.rk.loadRKM('All')``); a method with floating-point coefficients is refused with
its name and the first inexact entry, as a tableau file with a decimal is: nothing is rounded
to a guess.  An embedded pair keeps its b̂ (``RungeKutta.bhat``) when it is exact too, else the
method comes without it, with a note saying so.
:func:`to_nodepy` gives NodePy the exact method back.  From plain data there is
``RungeKutta.from_lists`` and the constructors of :mod:`methods` (sympy matrices, lists of ints,
sympy numbers; every entry validated like a file's).

>>> from tableau_lab.exact.interop import from_lists
>>> from_lists([[0, 0], ["1/2", 0]], [0, 1], name="midpoint").c.T
Matrix([[0, 1/2]])
"""
from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import sympy as sp

from .grammar import parse_entry
from .methods import GeneralLinearMethod, MethodError, RungeKutta

__all__ = ["from_nodepy", "to_nodepy", "from_lists", "InexactMethod"]


class InexactMethod(MethodError):
    """A method whose coefficients are floating-point numbers: not an exact tableau."""


def _exact(x: object, where: str, name: str) -> sp.Expr:
    if isinstance(x, (bool, np.bool_)):
        raise MethodError(f"{name}: {where} is a boolean, not a number")
    if isinstance(x, (int, np.integer)):
        return sp.Integer(int(x))
    if isinstance(x, sp.Basic):
        if x.free_symbols:
            return x
        if x.has(sp.Float) or not x.is_number:
            raise InexactMethod(f"{name}: {where} = {x} is not exact (floating-point coefficients)")
        return x
    if isinstance(x, (float, np.floating)):
        raise InexactMethod(f"{name}: {where} = {x!r} is a floating-point number, not an exact coefficient")
    if isinstance(x, str):
        return parse_entry(x)            # the safe grammar, never sympify on text
    raise MethodError(f"{name}: {where} has type {type(x).__name__}, not a number")


def from_nodepy(rkm: Any) -> RungeKutta | GeneralLinearMethod:
    """The exact :class:`RungeKutta` of a NodePy ``RungeKuttaMethod`` (module docstring); a NodePy
    ``LinearMultistepMethod`` (α, β exact) becomes the GLM of :func:`multistep.lmm`."""
    name = str(getattr(rkm, "name", "") or "NodePy method")
    if hasattr(rkm, "alpha") and hasattr(rkm, "beta") and not hasattr(rkm, "A"):
        return _lmm_from_nodepy(rkm, name)
    A = np.asarray(rkm.A, dtype=object)
    b = np.asarray(rkm.b, dtype=object).ravel()
    s = len(b)
    if A.shape != (s, s):
        raise MethodError(f"{name}: A has shape {A.shape}, b has {s} entries")
    Ax = [[_exact(A[i, j], f"A[{i + 1},{j + 1}]", name) for j in range(s)] for i in range(s)]
    bx = [_exact(b[j], f"b[{j + 1}]", name) for j in range(s)]
    bhat, bh, notes = getattr(rkm, "bhat", None), None, tuple[str, ...]()
    if bhat is not None:
        try:
            bh = sp.ImmutableMatrix([_exact(x, f"bhat[{j + 1}]", name)
                                     for j, x in enumerate(np.asarray(bhat, dtype=object).ravel())])
        except InexactMethod as exc:        # an exact method with a floating-point embedded b̂ (SSP33)
            notes = (f"embedded weights not kept: {exc}",)
    return RungeKutta(A=sp.ImmutableMatrix(Ax), b=sp.ImmutableMatrix(bx), bhat=bh, name=name, notes=notes,
                      source=f"NodePy {_version()} ({getattr(rkm, 'shortname', '') or name})")


def _lmm_from_nodepy(lmm_: Any, name: str) -> GeneralLinearMethod:
    from .multistep import lmm
    alpha = [_exact(x, f"alpha[{j + 1}]", name) for j, x in enumerate(np.asarray(lmm_.alpha, dtype=object).ravel())]
    beta = [_exact(x, f"beta[{j + 1}]", name) for j, x in enumerate(np.asarray(lmm_.beta, dtype=object).ravel())]
    return lmm(alpha, beta, name=name, source=f"NodePy {_version()} ({getattr(lmm_, 'shortname', '') or name})")


def to_nodepy(m: RungeKutta) -> Any:
    """The method as a NodePy ``RungeKuttaMethod`` with exact (sympy) coefficients."""
    from nodepy import rk
    if m.kind != "rk":
        raise TypeError(f"NodePy's RungeKuttaMethod holds Runge–Kutta methods, not {m.kind!r}")
    A = np.array([[m.A[i, j] for j in range(m.s)] for i in range(m.s)], dtype=object)
    b = np.array(list(m.b), dtype=object)
    return rk.RungeKuttaMethod(A, b, name=m.name)


def from_lists(A: Sequence[Sequence[object]], b: Sequence[object], c: Sequence[object] | None = None,
               **meta: Any) -> RungeKutta:
    """An RK method from lists of ints, sympy numbers or entries in the tableau grammar
    ("1/2", "sqrt(3)/6"); floats are refused."""
    name = meta.get("name", "method")
    s = len(b)
    Ax = [[_exact(x, f"A[{i + 1},{j + 1}]", name) for j, x in enumerate(row)] for i, row in enumerate(A)]
    bx = [_exact(x, f"b[{j + 1}]", name) for j, x in enumerate(b)]
    cx = None if c is None else [_exact(x, f"c[{j + 1}]", name) for j, x in enumerate(c)]
    if any(len(row) != s for row in Ax) or len(Ax) != s:
        raise MethodError(f"{name}: A must be {s}×{s} for {s} weights")
    return RungeKutta.from_lists(Ax, bx, cx, **meta)


def _version() -> str:
    from importlib.metadata import PackageNotFoundError, version
    try:
        return version("nodepy")
    except PackageNotFoundError:          # pragma: no cover
        return ""
