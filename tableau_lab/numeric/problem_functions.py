"""A problem's numeric functions — f, f′, the invariants, their gradients, the derivatives
f⁽ᵐ⁾ and the elementary differentials F(t) — evaluated from generated code, in float64
(numpy) or mpmath.  Where the code comes from is the subclass's business:
:class:`~.codegen.CompiledProblem` generates it from the problem's symbols (sympy), and
:class:`~.frozen.FrozenProblem` holds it as text, so that a run can go on in a process that
never imports sympy.  Nothing here imports it.

The elementary differentials are those of Butcher (*Numerical Methods for Ordinary
Differential Equations*, 3rd ed., 2016, §31): F(τ) = f, F([t₁ … t_m]) = f⁽ᵐ⁾(F(t₁), …, F(t_m)).
"""
from __future__ import annotations

import mpmath
import numpy as np

from ..analysis.trees import trees_up_to
from ..errors import InputError

__all__ = ["ProblemError", "ProblemFunctions"]


class ProblemError(InputError):
    """A problem definition, parameter or value that cannot be used."""


class ProblemFunctions:
    """Vectors in and out are numpy arrays, of float64 or (mpmath) of mpf with dtype=object, so
    that +, * and @ work alike in both precisions; mpmath inputs may also be lists or mpmath
    matrices.  mpmath evaluates at ``dps`` digits.  Subclasses set ``problem`` (with ``name``,
    ``kind``, ``invariants``, ``dimension``), ``backend``, ``dps``, ``constants``, ``y0`` and
    implement ``_code(what)``: the generated function for "f", "jac", ("invariant", name),
    ("gradient", name) or ("derivative", m), called as fn(y, constants, *vectors)."""

    problem = None
    backend = "numpy"
    dps = None
    constants: list = []

    def _code(self, what):
        raise NotImplementedError

    def __getstate__(self):
        state = dict(self.__dict__)
        for k in ("_functions", "_composed"):   # generated and composed functions: made again where unpickled
            if k in state:
                state[k] = {}
        return state

    def generated(self, what):
        """The generated function of ``what`` (as ``_code``) as it is: fn(y, constants, *vectors),
        returning lists (a number for an invariant), without conversions or a floating-point error
        state: for a loop that calls it many times inside its own (:func:`.kernels.pure_loop`)."""
        return self._code(what)

    # -- conversions --------------------------------------------------------------------------
    def _vector(self, values):
        if self.backend == "numpy":
            return np.array(values, dtype=float)
        with mpmath.workdps(self.dps):
            return np.array([mpmath.mpf(v) for v in values], dtype=object)

    def _input(self, y):
        if self.backend == "numpy":
            return np.asarray(y, dtype=float)
        if isinstance(y, mpmath.matrix):
            y = [y[i] for i in range(y.rows * y.cols)]
        return self._vector(y)

    def _evaluating(self):
        """Where generated code runs: numpy's error state (inf/NaN: the driver reports them) or
        mpmath's precision."""
        if self.backend == "numpy":
            return np.errstate(over="ignore", invalid="ignore", divide="ignore")
        return mpmath.workdps(self.dps)

    def _call(self, fn, y, *extra):
        with self._evaluating():
            return fn(self._input(y), self.constants, *extra)

    def _known_invariant(self, name):
        if name not in self.problem.invariants:
            raise ProblemError(f"problem {self.problem.name!r} has no invariant {name!r}; "
                               f"known: {', '.join(self.problem.invariants) or 'none'}")

    # -- the functions ------------------------------------------------------------------------
    def f(self, y):
        """f(y)."""
        return self._vector(self._call(self._code("f"), y))

    def jac(self, y):
        """The Jacobian f'(y)."""
        rows = self._call(self._code("jac"), y)
        if self.backend == "numpy":
            return np.array(rows, dtype=float)
        return np.array([self._vector(row) for row in rows], dtype=object)

    def invariant(self, name, y):
        """The invariant ``name`` at y (a float or an mpf)."""
        self._known_invariant(name)
        v = self._call(self._code(("invariant", name)), y)
        return float(v) if self.backend == "numpy" else self._vector([v])[0]

    def gradient(self, name, y):
        """The gradient of the invariant ``name`` at y."""
        self._known_invariant(name)
        return self._vector(self._call(self._code(("gradient", name)), y))

    def derivative(self, m):
        """(y, u₁, …, u_m) -> f⁽ᵐ⁾(y)(u₁, …, u_m), the m-th derivative of f applied to m vectors."""
        fn = self._code(("derivative", m))
        return lambda y, *us: self._vector(self._call(fn, y, *[self._input(u) for u in us]))

    def elementary_differentials(self, order: int):
        """A function y -> {tree: F(t)(y)} for every rooted tree t with |t| ≤ order (trees of
        ``analysis.trees``).  Only the derivatives f⁽ᵐ⁾ are generated; F(t) is composed
        numerically, children first, so no expression grows with the tree."""
        composed = self.__dict__.setdefault("_composed", {})
        if order in composed:               # built once per order: a run calls it at every record
            return composed[order]
        trees = list(trees_up_to(order))
        codes = {m: self._code(("derivative", m)) if m else self._code("f") for m in {len(t) for t in trees}}
        c, vector = self.constants, self._vector

        def F(y):
            out = {}
            with self._evaluating():              # once: the derivatives' vectors are out's, converted
                y = self._input(y)
                for t in trees:                   # by order: children come first
                    out[t] = vector(codes[len(t)](y, c, *(out[k] for k in t)))
            return out
        composed[order] = F
        return F
