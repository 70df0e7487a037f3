r"""One integrator for every method kind, in float64 or mpmath ([B16] ch. 5 for the GLM step;
[HLW06] VII.1 and the seed's §3.2 for projection).

A step of the partitioned GLM of :mod:`export` on y' = f(y) with input values y^[n−1] (r × d):

    Yᵢ = Σₖ Uᵢₖ y^[n−1]ₖ + h Σⱼ (A_q[i,j] P_q + A_p[i,j] P_p) f(Yⱼ)
    y^[n]ₖ = Σₗ Vₖₗ y^[n−1]ₗ + h Σⱼ (B_q[k,j] P_q + B_p[k,j] P_p) f(Yⱼ)

(P_q, P_p: the masks of the q- and p-components).  Explicit methods evaluate the stages in
order; implicit ones solve the stage system by simplified Newton with the Jacobian of f at the
step's first stage input (I − h(A_q ⊗ P_qJ + A_p ⊗ P_pJ) factorised once per step) and fall back
to fixed-point iteration; the tolerance follows the precision (10 ulp in float64, 10^(2−dps) in
mpmath).  A stage system that does not converge, and any NaN or overflow, stops the run with
:class:`IntegrationError` naming the step, the time and the residual.  When V's first row is
e₁ᵀ (RK and partitioned RK methods, and G-symplectic GLMs written with the principal value
first), the first output is an increment and is summed with compensation (Kahan).

GLM runs start from the exported starting method (elementary differentials of f at y₀), or
naively (y^[0] = u y₀), and report the principal value through the finishing method.
Projection (optional) moves the first output value onto {I_k(y) = I_k(y₀)} for the chosen
invariants by simplified Newton on the multipliers: y = ỹ + ∇g(ỹ)λ.

*Parasitism monitor* (GLMs whose V has eigenvalues ζ ≠ 1 on the unit circle, [BHHN14]).  At
every record the parasitic component of each such ζ is measured: with y_ζ the left eigenvector
of V (y_ζ x_ζ = 1) and S_h(ŷ) the starting method applied to the finished value ŷ (the input
vector the smooth solution through ŷ would have; u ŷ after a naive start),

    c_ζ = Σ_k (y_ζ)_k (y^[n]_k − S_h(ŷ)_k),   recorded as max_i |c_ζ,i|

(removing S_h(ŷ) keeps the smooth O(h^k) part of the non-principal values from hiding a
component that starts at round-off), beside the predicted log-growth ∫ max Re eig(μ_ζ f′(ŷ)) dt
(trapezoidal rule over the records).  ``monitor=BOUND`` stops the run with
:class:`ParasiticBoundExceeded` (an IntegrationError with the records so far) when a component
exceeds BOUND; the bound is checked at the records only, every ``record_every`` steps.
"""
from __future__ import annotations

import os
import time
from dataclasses import dataclass, field

import numpy as np

from ..analysis.trees import order as tree_order, symmetry
from .arith import is_exact
from .method import NumericMethod
from ..analysis.growth import growth_rate

__all__ = ["integrate", "Run", "IntegrationError", "ParasiticBoundExceeded", "start_values", "finish",
           "component_masks"]


class IntegrationError(RuntimeError):
    """A run that cannot continue; the message names step, time and the reason."""


class ParasiticBoundExceeded(IntegrationError):
    """The parasitism monitor stopped the run: a parasitic component exceeded the bound.
    ``step``, ``t``, ``zeta`` (as printed), ``value``, ``bound``, ``mu``."""


@dataclass
class Run:
    method: str
    problem: str
    precision: str
    h: float
    steps: int
    start: str
    projected: tuple
    times: list = field(default_factory=list)           # recorded times
    values: list = field(default_factory=list)          # recorded (finished) states at the working precision
    invariant_errors: dict = field(default_factory=dict)  # name -> [I(y) − I(y0)] at the records
    final: object = None                                 # finished state at the end
    nfev: int = 0
    newton_iterations: int = 0
    projection_iterations: int = 0
    seconds: float = 0.0
    completed: int = 0                                   # steps done
    parasitic: list = field(default_factory=list)        # max |y^[n]_k|, k ≥ 2, at the records (GLMs)
    parasitic_components: dict = field(default_factory=dict)  # ζ -> max_i |c_ζ,i| at the records (module docstring)
    predicted_growth: dict = field(default_factory=dict)  # ζ -> ∫₀ᵗ max Re eig(μ f′(ŷ)) dt at the records (μ ≠ 0)
    growth_parameters: dict = field(default_factory=dict)  # ζ -> μ (complex float)
    compile_seconds: float = 0.0                         # compiled kernel: first call (compile or cache load)
    tracked: dict = field(default_factory=dict)         # compiled loop: name -> max |I(y^[n]_1) − I(y0)| over all steps

    def max_invariant_error(self) -> dict:
        """Largest |I − I(y0)| at the records, and over every step where the compiled loop
        tracked it."""
        return {k: max([abs(float(x)) for x in v] + [self.tracked.get(k, 0.0)])
                for k, v in self.invariant_errors.items()}


def start_values(nm: NumericMethod, prob, y0, h, start: str = "exact"):
    """y^[0] (r × d): u y₀ plus, with ``start="exact"``, the starting method's B-series terms."""
    a = nm.arith
    Y = np.array([nm.u[k] * y0 for k in range(nm.r)], dtype=a.dtype)
    if start == "naive" or not nm.starting:
        return Y
    p = max((tree_order(t) for t in nm.starting), default=0)
    F = prob.elementary_differentials(p)(y0)
    for t, xi in nm.starting.items():
        coef = h ** tree_order(t) / symmetry(t)
        for k in range(nm.r):
            if xi[k] != 0:
                Y[k] = Y[k] + (xi[k] * coef) * F[t]
    return Y


def finish(nm: NumericMethod, prob, Y, h, series: bool = True):
    """The approximation of y(t) from y^[n]: z + Σ α⁻¹(t) h^|t|/σ(t) F(t)(z), z = wᵀy^[n]
    (only z with ``series=False``, as after a naive start)."""
    z = Y[0] if nm.r == 1 else sum((nm.w[k] * Y[k] for k in range(nm.r)), 0 * Y[0])
    if not (series and nm.finishing):
        return z
    p = max(tree_order(t) for t in nm.finishing)
    F = prob.elementary_differentials(p)(z)
    out = z.copy()
    for t, beta in nm.finishing.items():
        if beta != 0:
            out = out + (beta * h ** tree_order(t) / symmetry(t)) * F[t]
    return out


class _Stepper:
    def __init__(self, nm: NumericMethod, prob, h, d, masks, compensated: bool = True, fixed: bool = False):
        self.nm, self.prob, self.h = nm, prob, h
        self.fixed = fixed                         # stage iteration: fixed point instead of simplified Newton
        self.a = nm.arith
        self.mq, self.mp = masks
        self.s, self.r, self.d = nm.s, nm.r, d
        self.nfev = 0
        self.newton = 0
        first_is_increment = bool(nm.V[0, 0] == 1 and all(nm.V[0, k] == 0 for k in range(1, nm.r)))
        self.comp = self.a.zeros(d) if first_is_increment and compensated else None
        self.tol = self.a.tol
        self.Fprev = None                          # the last step's stage derivatives (predictor)
        self.hA = 0.0 if nm.explicit else _stage_scale(nm, h)
        if not nm.explicit:                        # per method, not per step
            self.eye = self._identity(nm.s * d)

    def f(self, y):
        self.nfev += 1
        return self.prob.f(y)

    def stages(self, Ubar, n, t):
        nm, h = self.nm, self.h
        s = self.s
        if nm.explicit:
            F = []
            for i in range(s):
                Y = Ubar[i].copy()
                for j in range(i):
                    if nm.Aq[i, j] != 0 or nm.Ap[i, j] != 0:
                        Y = Y + h * (nm.Aq[i, j] * self.mq + nm.Ap[i, j] * self.mp) * F[j]
                F.append(self.f(Y))
            return np.array(F, dtype=self.a.dtype)
        return self._newton(Ubar, n, t)

    def _rhs(self, F):
        return self.h * ((self.nm.Aq @ F) * self.mq + (self.nm.Ap @ F) * self.mp)

    def _identity(self, k):
        a = self.a
        if a.dtype is object:
            return np.array([[a.number(1) if i == j else a.number(0) for j in range(k)] for i in range(k)], dtype=object)
        return np.eye(k)

    def _newton_matrix(self, Js):
        """I − h Σ_j (A_q[:, j] ⊗ P_q J_j + A_p[:, j] ⊗ P_p J_j), J_j the Jacobian for stage j."""
        nm, h, s, d = self.nm, self.h, self.s, self.d
        M = self.eye.copy()
        for j, J in enumerate(Js):
            Jq, Jp = J * self.mq[:, None], J * self.mp[:, None]
            for i in range(s):
                if nm.Aq[i, j] != 0 or nm.Ap[i, j] != 0:
                    M[i * d:(i + 1) * d, j * d:(j + 1) * d] -= h * (nm.Aq[i, j] * Jq + nm.Ap[i, j] * Jp)
        return M

    def _newton(self, Ubar, n, t):
        """Simplified Newton (one Jacobian, at the first stage input), started from the previous
        step's stage derivatives extrapolated to the new stages (``nm.E``; GNI's start) and
        stopped by Hairer's estimate θ/(1 − θ)·‖ΔY‖ ≤ tol, θ the contraction rate; if it
        stalls, again from Ū, then full Newton (Jacobians at the current stage values,
        refreshed each iteration); then fixed point.  Returns the stage derivatives: from the
        increments, A⁻¹(Y − Ū)/h, when A is invertible (no f-evaluation after convergence)."""
        a, s, d = self.a, self.s, self.d
        fixed = self.fixed                 # fixed-point iteration: the same loop with M = I
        J0 = None if fixed else self.prob.jac(Ubar[0])
        # attainable accuracy: round-off amplified by the conditioning of the stage system
        amp = 1 if fixed else 1 + self.hA * (float(np.max(np.abs(a.to_float(J0.reshape(-1))))) if J0.size else 0.0)
        # iterate on the increments Z = Y − Ū (small, so A⁻¹Z keeps its relative precision)
        starts = [a.zeros(s, d)]
        if self.Fprev is not None and self.nm.E is not None:
            starts.insert(0, self._rhs(self.nm.E @ self.Fprev))
        tries = [(Z0, False) for Z0 in starts] + [(starts[-1], True)]
        Minv = None
        scale = 1 + a.norm(Ubar.reshape(-1))
        for Z0, full in tries:
            if Minv is None and not full and not fixed:
                Minv = a.lu(self._newton_matrix([J0] * s))
            Z, prev = Z0.copy(), None
            for it in range(60 if not full else 30):
                Y = Ubar + Z
                F = np.array([self.f(Y[i]) for i in range(s)], dtype=a.dtype)
                M = a.lu(self._newton_matrix([self.prob.jac(Y[j]) for j in range(s)])) if full else Minv
                R = self._rhs(F) - Z
                dZ = R if (fixed and not full) else a.lu_solve(M, R.reshape(-1)).reshape(s, d)
                Z = Z + dZ
                self.newton += 1
                if not a.finite(dZ.reshape(-1)):
                    break
                size = a.norm(dZ.reshape(-1))
                # to an ulp of the increments themselves: A⁻¹Z/h feeds the output unscaled by h
                if _converged(size, prev, a.eps * a.norm(Z.reshape(-1)), 1000 * a.eps * scale * amp):
                    return self._derivatives(Z, Ubar)
                if prev is not None and it > 3 and size > prev:
                    break                   # diverging
                prev = size
        return self._fixed_point(Ubar, n, t)

    def _derivatives(self, Z, Ubar):
        """The stage derivatives f(Yᵢ) of converged stages Y = Ū + Z: A⁻¹Z/h per component
        class when A_q and A_p are invertible, else evaluated.  Kept for the next step's start."""
        nm = self.nm
        if nm.Aq_inv is not None and nm.Ap_inv is not None:
            F = (1 / self.h) * ((nm.Aq_inv @ Z) * self.mq + (nm.Ap_inv @ Z) * self.mp)
        else:
            Y = Ubar + Z
            F = np.array([self.f(Y[i]) for i in range(self.s)], dtype=self.a.dtype)
        self.Fprev = F
        return F

    def _fixed_point(self, Ubar, n, t):
        a, s = self.a, self.s
        Y = Ubar.copy()
        F = np.array([self.f(Y[i]) for i in range(s)], dtype=a.dtype)
        size = prev = float("inf")
        for _ in range(200):
            Ynew = Ubar + self._rhs(F)
            size = a.norm((Ynew - Y).reshape(-1))
            Y = Ynew
            if not a.finite(Y.reshape(-1)):
                break
            F = np.array([self.f(Y[i]) for i in range(s)], dtype=a.dtype)
            scale = 1 + a.norm(Y.reshape(-1))
            if size <= self.tol * scale or (size >= 0.9 * prev and size <= 1000 * a.eps * scale):
                self.Fprev = F
                return F
            prev = size
        raise IntegrationError(f"step {n} (t = {float(t):.6g}): the implicit stage equations did not converge "
                               f"(simplified and full Newton, then fixed-point iteration; last correction {size:.3g}, "
                               f"tolerance {self.tol:.3g}); try a smaller step size h = {float(self.h):.6g}")

    def step(self, Yin, n, t):
        nm, h = self.nm, self.h
        Ubar = nm.U @ Yin
        F = self.stages(Ubar, n, t)
        inc = h * ((nm.Bq @ F) * self.mq + (nm.Bp @ F) * self.mp)
        Yout = nm.V @ Yin + inc
        if self.comp is not None:                  # Kahan summation of the principal increment
            x = inc[0] + self.comp
            y1 = Yin[0] + x
            self.comp = (Yin[0] - y1) + x
            Yout[0] = y1
        return Yout


class _Monitor:
    """The parasitic components of the input vector at the records, the predicted log-growth
    along the run, and the bound (see the module docstring)."""

    def __init__(self, nm, prob, h, start, bound, run):
        self.nm, self.prob, self.h, self.start, self.bound, self.run = nm, prob, h, start, bound, run
        self.modes = nm.modes or ()
        if bound is not None and not bound > 0:
            raise ValueError(f"monitor: the bound must be positive, not {bound!r}")
        self.L = np.array([m.left for m in self.modes]) if self.modes else None     # modes × r
        run.parasitic_components = {m.label: [] for m in self.modes}
        run.predicted_growth = {m.label: [] for m in self.modes if m.mu != 0}
        run.growth_parameters = {m.label: m.mu for m in self.modes}
        self.last = None                                     # (t, rates) at the previous record
        self.first = {}                                      # ζ -> (record index, t) of its first nonzero size

    def __call__(self, n, Y, y):
        if not self.modes:
            return
        nm, run, a = self.nm, self.run, self.nm.arith
        S = start_values(nm, self.prob, y, self.h, self.start)
        D = np.array([a.to_float(Y[k] - S[k]) for k in range(nm.r)])            # r × d
        sizes = np.max(np.abs(self.L @ D), axis=1) if D.size else np.zeros(len(self.modes))
        t = float(n * self.h)
        if run.predicted_growth:
            J = a.to_float(np.asarray(self.prob.jac(y)).reshape(-1)).reshape(len(y), len(y))
            rates = {m.label: growth_rate(m.mu, J) for m in self.modes if m.mu != 0}
            for k, v in rates.items():
                acc = run.predicted_growth[k]
                acc.append(acc[-1] + (t - self.last[0]) * (v + self.last[1][k]) / 2 if acc else 0.0)
            self.last = (t, rates)
        for m, v in zip(self.modes, sizes):
            run.parasitic_components[m.label].append(float(v))
            if m.label not in self.first and v > 0:              # the first nonzero record: growth from here
                self.first[m.label] = (len(run.times) - 1, t)
        if self.bound is None:
            return
        for m, v in zip(self.modes, sizes):
            if not v <= self.bound:                            # NaN stops too
                run.completed = n
                mu = m.mu.real if m.mu.imag == 0 else m.mu
                err = ParasiticBoundExceeded(f"step {n} (t = {t:.6g}): parasitic component ζ = {m.label} reached "
                                             f"{v:.3g} > bound {self.bound:.3g} (growth parameter μ = {mu:.6g}"
                                             + self._growth(m.label, v) + ")")
                err.step, err.t, err.zeta, err.value, err.bound, err.mu = n, t, m.label, float(v), self.bound, m.mu
                raise err

    def _growth(self, label, v) -> str:
        """"; since t = t₀: measured log-growth …, predicted …" for the stop message."""
        if label not in self.first or label not in self.run.predicted_growth:
            return ""
        k, t0 = self.first[label]
        P, c = self.run.predicted_growth[label], self.run.parasitic_components[label]
        return (f"; since t = {t0:.4g}: measured log-growth log(c/c₀) = {np.log(v / c[k]):.3g}, predicted "
                f"∫ max Re eig(μ f′) dt = {P[-1] - P[k]:.3g}")


def _converged(size, prev, tol, floor) -> bool:
    """Stop a contracting iteration: the correction is below tol, or Hairer's error estimate
    θ/(1 − θ)·‖Δ‖ (θ = ‖Δ‖/‖Δ_prev‖) is, or it stagnates (θ ≥ 0.9) at the round-off floor."""
    if size <= tol:
        return True
    if prev is None or prev == 0:
        return False
    theta = size / prev
    return (theta < 1 and theta / (1 - theta) * size <= tol) or (theta >= 0.9 and size <= floor)


def _project(prob, names, targets, y, a, n, t):
    """y + ∇g(y)λ with g = invariants − targets, Newton on λ (matrix ∇g(z)ᵀ∇g(y), refreshed each
    iteration); returns (y, iterations).
    Converged when g is at the tolerance relative to the size of the invariants' terms, or when
    the corrections stop shrinking (by half a sweep) with g already at round-off level (1000 ulp)."""
    G = np.array([prob.gradient(k, y) for k in names], dtype=a.dtype).T          # d × m
    inv = a.lu(G.T @ G)
    lam = a.zeros(len(names))
    # the size of the invariants' terms, not only of their values (FPU: ω²q² terms of a small
    # H): |I| + Σ|∂I/∂y_l · y_l| bounds the round-off of evaluating I
    yf = a.to_float(y)
    scale = 1 + max(abs(float(targets[k])) + float(np.sum(np.abs(a.to_float(G[:, j]) * yf)))
                    for j, k in enumerate(names))
    z, prev = y, None
    for it in range(50):
        g = np.array([prob.invariant(k, z) - targets[k] for k in names], dtype=a.dtype)
        res = a.norm(g) / scale
        if res <= a.tol:
            return z, it
        if it > 0:                          # Newton on λ: ∇g(z)ᵀ G at the current point
            Gz = np.array([prob.gradient(k, z) for k in names], dtype=a.dtype)
            inv = a.lu(Gz @ G)
        dl = -a.lu_solve(inv, g)
        step = a.norm(dl)
        if prev is not None and step >= 0.5 * prev and res <= 1000 * a.eps:   # stalled at round-off
            return z, it
        prev = step
        lam = lam + dl
        z = y + G @ lam
    if res <= 1e4 * a.eps:                  # round-off noise of a large-term invariant (FPU), not divergence
        return z, 50
    raise projection_failed(names, n, t, res)


def projection_failed(names, n, t, res) -> IntegrationError:
    return IntegrationError(f"step {n} (t = {float(t):.6g}): projection onto {', '.join(names)} did not converge "
                            f"(residual {res:.3g} after 50 iterations)")


def not_finite(n, t) -> IntegrationError:
    return IntegrationError(f"step {n} (t = {float(t):.6g}): the solution is not finite (NaN or overflow): the "
                            "method is unstable at this step size, or the problem is singular here")


def component_masks(prob, d: int):
    """(P_q, P_p) as 0/1 vectors: q and p halves for a Hamiltonian problem, all q otherwise."""
    problem = getattr(prob, "problem", None)
    if problem is not None and problem.kind == "hamiltonian":
        k = len(problem.q)
        return ([1] * k + [0] * k, [0] * k + [1] * k)
    return ([1] * d, [0] * d)


def _fixed_point(solver, nm, prob, y0, h, d) -> bool:
    """Stage iteration: "newton" (simplified Newton), "fixedpoint" (no Jacobian, no LU: for
    non-stiff problems with many components, as GNI's codes do), or "auto": fixed point when
    s·d > 24 and h·s·max|A|·ρ(f'(y0)) < 0.1 (the iteration then contracts by ≲ 0.1 a sweep)."""
    if solver not in ("auto", "newton", "fixedpoint"):
        raise ValueError(f"solver must be 'auto', 'newton' or 'fixedpoint', not {solver!r}")
    if nm.explicit or solver == "newton":
        return False
    if solver == "fixedpoint":
        return True
    if nm.s * d <= 24:
        return False
    J = nm.arith.to_float(prob.jac(y0).reshape(-1)).reshape(d, d)
    # the spectral radius, not the largest entry: q' = p/m has huge entries 1/m and small eigenvalues
    return _stage_scale(nm, h) * float(np.max(np.abs(np.linalg.eigvals(J)))) < 0.1


def _stage_scale(nm, h) -> float:
    """h·s·max|A|: how strongly h f' enters the stage equations (Newton's round-off floor, the
    fixed-point contraction)."""
    return abs(float(h)) * nm.s * float(np.max(np.abs(nm.arith.to_float(nm.Aq.reshape(-1)))))


def _use_kernel(kernel, a, prob) -> bool:
    if kernel not in ("auto", "compiled", "python"):
        raise ValueError(f"kernel must be 'auto', 'compiled' or 'python', not {kernel!r}")
    if kernel == "auto":                   # $TABLEAU_LAB_KERNEL=python: the pure loop unless asked
        kernel = os.environ.get("TABLEAU_LAB_KERNEL", "auto")
    if a.name == "dd":                     # double-double exists only compiled
        if not hasattr(prob, "problem"):
            raise ValueError("precision dd runs compiled: it needs a generated problem (compile_problem)")
        return True
    ok = a.name == "float64" and getattr(prob, "backend", None) == "numpy" and hasattr(prob, "problem")
    if kernel == "compiled" and not ok:
        raise ValueError("the compiled kernel runs float64 or dd on a generated problem (compile_problem)")
    if kernel == "python" or not ok:
        return False
    from .kernels import available
    return available()


def integrate(nm: NumericMethod, prob, y0, h, steps: int, *, start: str = "exact", project=(),
              invariants=(), record_every: int | None = None, record_states: bool = False,
              masks=None, problem_name: str = "", progress=None, compensated: bool = True,
              kernel: str = "auto", monitor: float | None = None, solver: str = "auto") -> Run:
    """Run ``steps`` steps of size h from y0 (a state vector at the method's precision).

    ``prob`` is a compiled problem (``f``, ``jac`` for implicit methods, ``invariant`` and
    ``gradient`` for projection/records, ``elementary_differentials`` for GLM starts).
    Records every ``record_every`` steps (and the last): time, invariant errors, and states
    if ``record_states``; memory grows with the records only.  ``compensated=False`` turns the
    Kahan summation of the principal increment off (to measure what it buys).  ``solver``:
    the stage iteration (see :func:`_fixed_point`).
    ``kernel``: "compiled" runs the float64 step loop compiled (:mod:`kernels`), "python" the
    loop here, "auto" the compiled one when the arithmetic is float64 and the problem is a
    generated one (same algorithm; results agree to round-off), unless the environment
    variable TABLEAU_LAB_KERNEL is "python".  Precision dd always runs compiled.
    ``monitor``: a bound on the parasitic components of a GLM's input vector, checked at the
    records; exceeding it raises :class:`ParasiticBoundExceeded` (module docstring).  The
    components and the predicted growth are recorded with or without a bound."""
    a = nm.arith
    with a.context():
        y0 = np.array(list(y0), dtype=a.dtype)
        d = len(y0)
        if masks is None:
            masks = component_masks(prob, d)
        masks = tuple(np.array([a.number(int(x)) if a.dtype is object else float(x) for x in m], dtype=a.dtype)
                      for m in masks)
        if isinstance(h, int) or is_exact(h):
            h = a.number(h)                        # exact step sizes (1/100) are rounded once, here
        elif a.dtype is object and not hasattr(h, "_mpf_"):
            import mpmath
            from fractions import Fraction
            q = Fraction(repr(float(h)))           # a float: the decimal it prints as, rounded once
            h = mpmath.mpf(q.numerator) / q.denominator
        run = Run(nm.name, problem_name, a.name, float(h), steps,
                  start if (nm.r > 1 or nm.starting) else "identity", tuple(project))
        names = tuple(dict.fromkeys(tuple(invariants) + tuple(project)))
        targets = {k: prob.invariant(k, y0) for k in names}
        run.invariant_errors = {k: [] for k in names}
        stepper = _Stepper(nm, prob, h, d, masks, compensated, _fixed_point(solver, nm, prob, y0, h, d))
        t0 = time.perf_counter()
        Y = start_values(nm, prob, y0, h, start)
        every = record_every or max(1, steps // 1000)

        def principal(Y):
            return finish(nm, prob, Y, h, series=start == "exact")

        watch = _Monitor(nm, prob, h, start, None if monitor is None else float(monitor), run)

        def record(n, Y):
            y = principal(Y)
            if nm.r > 1:
                run.parasitic.append(max(a.norm(Y[k]) for k in range(1, nm.r)))
            run.times.append(float(n * h))
            for k in names:
                run.invariant_errors[k].append(prob.invariant(k, y) - targets[k])
            if record_states:
                run.values.append(y.copy())          # at the working precision
            watch(n, Y, y)

        def project_step(y, n):
            return _project(prob, tuple(project), targets, y, a, n, n * h)

        record(0, Y)
        try:
            if _use_kernel(kernel, a, prob):
                from .kernels import drive
                Y = drive(nm, prob, Y, h, steps, every, masks=masks, project=tuple(project), targets=targets,
                          stepper=stepper, record=record, progress=progress, run=run,
                          project_step=project_step if project else None, track=names)
            for n in range(run.completed + 1, steps + 1):
                Y = stepper.step(Y, n, n * h)
                if project:
                    Y[0], its = project_step(Y[0], n)
                    run.projection_iterations += its
                if not a.finite(Y.reshape(-1)):
                    raise not_finite(n, n * h)
                run.completed = n
                if n % every == 0 or n == steps:
                    record(n, Y)
                    if progress is not None:
                        progress(n)
        except KeyboardInterrupt as exc:
            exc.partial = run                      # the records so far, for a valid incomplete file
            raise
        except IntegrationError as exc:
            exc.partial = run
            if nm.r > 1 and len(run.parasitic) > 1 and not isinstance(exc, ParasiticBoundExceeded):
                k = int(np.argmin(run.parasitic))
                err = IntegrationError(f"{exc}. Non-principal input components max|y^[n]_k|, k ≥ 2: "
                                       f"{run.parasitic[k]:.2e} at t = {run.times[k]:.4g}, "
                                       f"{run.parasitic[-1]:.2e} at t = {run.times[-1]:.4g}"
                                       + (" (growing: parasitism?)" if run.parasitic[-1] > 10 * run.parasitic[k] else ""))
                err.partial = run
                raise err from None
            raise
        finally:
            run.nfev, run.newton_iterations = stepper.nfev, stepper.newton
            run.seconds = time.perf_counter() - t0 - run.compile_seconds
        run.final = principal(Y)
    return run

