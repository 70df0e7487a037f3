r"""One integrator for every method kind, in float64 or mpmath ([B16] ch. 5 for the GLM step;
[HLW06] VII.1 and the seed's §3.2 for projection).

The step itself — explicit stages, the stage iteration (simplified Newton, fixed point, or on
the q stages alone for separable problems) and its fallbacks, the GLM output with Kahan
summation of the principal increment, projection, invariant tracking and records — is
:mod:`stepcore`, written once and run compiled (float64, double-double) or in Python
(float64, mpmath) by :mod:`kernels`; this module prepares a run, starts and finishes it, and
turns the loop's outcome into a :class:`Run` or an :class:`IntegrationError` naming the step.

GLM runs start from the exported starting method (elementary differentials of f at y₀), or
naively (y^[0] = u y₀), and report the principal value through the finishing method.
Projection (optional) moves the first output value onto {I_k(y) = I_k(y₀)} for the chosen
invariants (Newton on the multipliers: y = ỹ + ∇g(ỹ)λ, in :mod:`stepcore`).

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

from ..analysis.growth import growth_rate
from ..analysis.trees import order as tree_order, symmetry
from . import background, kernels, limits
from .arith import is_exact
from .errors import IntegrationError, ParasiticBoundExceeded, not_finite, projection_failed, stages_failed
from .method import NumericMethod

__all__ = ["integrate", "step", "Run", "IntegrationError", "ParasiticBoundExceeded", "start_values", "finish",
           "component_masks", "stage_iteration"]


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
    loop_why: str = ""                                   # why this loop (kernel="cost": limits.choose_loop's reason)
    tracked: dict = field(default_factory=dict)         # name -> max |I(y^[n]_1) − I(y0)| every track_every steps
    velocity_evaluations: int = 0                        # separable problems: q-rate evaluations (nfev: forces)
    fallbacks: int = 0                                   # steps whose first stage iteration failed
    invariant_scales: dict = field(default_factory=dict)  # name -> |I(y0)| (1 where I(y0) = 0): "relative" below
    state_scale: float = 1.0                             # max |y0_i| (1 where y0 = 0): the parasitic components' scale
    loop: str = ""                                       # the step loop that ran: "compiled" (numba) or "python"
    switched_at: int | None = None                       # "python, then compiled": the last step before the switch

    def switched(self, step: int | None, to: str = "compiled") -> None:
        """The run went on another loop after ``step`` (None: it did not): the loop specialised to
        it (``to`` "compiled") or the loop shared by every problem ("linked")."""
        if step is not None:
            self.loop, self.switched_at = f"{self.loop}, then {to}", step

    def max_invariant_error(self) -> dict:
        """Largest |I − I(y0)| at the records, and over every step where the compiled loop
        tracked it."""
        return {k: max([abs(float(x)) for x in v] + [self.tracked.get(k, 0.0)])
                for k, v in self.invariant_errors.items()}

    def degraded(self) -> str:
        """Why a run that went to its end failed in substance, or "": an invariant error (largest
        |I − I(y0)|, over the records and the tracked steps) or a parasitic component of a GLM's
        input reaching ``limits.DEGRADED`` relative to |I(y0)| (to max |y0_i| for the
        components); NaN counts.

        >>> r = Run("m", "p", "float64", 0.1, 10, "identity", (), invariant_errors={"H": [0.0, 0.5]},
        ...         invariant_scales={"H": 0.7})
        >>> r.degraded()
        'H drifted by 5.00e-01, 0.714 of |H(y0)| (the bound: 0.01)'
        """
        why = []
        for k, v in self.max_invariant_error().items():
            scale = self.invariant_scales.get(k, 1.0)
            if not v < limits.DEGRADED * scale:
                why.append(f"{k} drifted by {v:.2e}, {v / scale:.3g} of |{k}(y0)| (the bound: {limits.DEGRADED:g})")
        for z, c in self.parasitic_components.items():
            big = max(c, default=0.0)
            if not big < limits.DEGRADED * self.state_scale:
                why.append(f"the parasitic component ζ = {z} reached {big:.2e}, {big / self.state_scale:.3g} of "
                           f"max |y0_i| (the bound: {limits.DEGRADED:g})")
        return "; ".join(why)

    def even_records(self) -> None:
        """Cut the per-record lists to their common length: a Ctrl-C that lands inside a record
        leaves the lists appended before it one entry longer than the rest.  The lists a run
        fills are those holding the first record (taken before the loop); the others stay empty."""
        filled = [x for x in (self.times, self.values, self.parasitic, *self.invariant_errors.values(),
                              *self.parasitic_components.values(), *self.predicted_growth.values()) if x]
        n = min(len(x) for x in filled)
        for x in filled:
            del x[n:]


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
        for m, v in zip(self.modes, sizes, strict=False):
            run.parasitic_components[m.label].append(float(v))
            if m.label not in self.first and v > 0:              # the first nonzero record: growth from here
                self.first[m.label] = (len(run.times) - 1, t)
        if self.bound is None:
            return
        for m, v in zip(self.modes, sizes, strict=False):
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


def component_masks(prob, d: int):
    """(P_q, P_p) as 0/1 vectors: q and p halves for a Hamiltonian problem, all q otherwise."""
    problem = getattr(prob, "problem", None)
    if problem is not None and problem.kind == "hamiltonian":
        k = len(problem.q)
        return ([1] * k + [0] * k, [0] * k + [1] * k)
    return ([1] * d, [0] * d)


def stage_iteration(solver, nm, prob, y0, h, d, split: bool = True) -> int:
    """The stage iteration mode (:func:`limits.choose_iteration`, the cheaper by its cost
    model): κ = h·‖A‖∞·ρ(f′(y₀)) from the Jacobian at y₀ (the spectral radius, not the largest
    entry: q′ = p/m has huge entries 1/m and small eigenvalues), f's price from the problem's
    expressions (d without them); the q stages alone for a separable problem unless ``split``
    is False (masks other than its q/p halves)."""
    if nm.explicit or solver == "newton":
        return limits.choose_iteration(solver, explicit=nm.explicit, separable=False, contraction=0.0)
    problem = getattr(prob, "problem", None)
    separable = split and bool(getattr(problem, "separable", False))
    contraction = 0.0
    if solver == "auto":
        J = nm.arith.to_float(prob.jac(y0).reshape(-1)).reshape(d, d)
        rho = float(np.max(np.abs(np.linalg.eigvals(J)))) if d else 0.0
        contraction = nm.stage_scale(h) * rho
    f_ops = getattr(problem, "operations", 0) or d
    return limits.choose_iteration(solver, explicit=False, separable=separable, contraction=contraction, s=nm.s,
                                   d=d, f_ops=f_ops, lower=nm.lower)


def _mode(solver, nm, prob, y0, h, masks) -> int:
    """:func:`stage_iteration`, with the q stages alone only where the masks are the problem's
    own q/p halves."""
    d = len(y0)
    own = [list(map(int, m)) for m in masks] == [list(m) for m in component_masks(prob, d)]
    return stage_iteration(solver, nm, prob, y0, h, d, split=own)


def _finite_start(nm, prob, y0, targets, precision) -> None:
    """Refuse a start where y0, f(y0), an invariant or (implicit methods, GLMs) f′(y0) is not
    finite at the working precision (e.g. q0 = 1e200: H = q²/2 overflows): step 0 named."""
    a = nm.arith
    parts = [("y0", y0), ("f(y0)", prob.f(y0)), *((f"{k}(y0)", np.array([v])) for k, v in targets.items())]
    if not nm.explicit or nm.r > 1:
        parts.append(("the Jacobian f′(y0)", np.asarray(prob.jac(y0)).reshape(-1)))
    for what, v in parts:
        x = a.to_float(np.asarray(v, dtype=a.dtype).reshape(-1))
        if not np.all(np.isfinite(x) & (np.abs(x) < limits.HUGE)):
            raise IntegrationError(f"step 0 (t = 0): {what} is not finite in {precision} (NaN or overflow): the "
                                   "initial value is out of the range this precision can run")


def _use_kernel(kernel, a, prob) -> bool:
    if kernel not in ("auto", "compiled", "python", "cost"):
        raise ValueError(f"kernel must be 'auto', 'compiled', 'python' or 'cost', not {kernel!r}")
    if kernel in ("auto", "cost"):         # $TABLEAU_LAB_KERNEL=python: the pure loop unless asked
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
    return kernels.available()


def _loop_reason(kernel: str, a, compiled) -> str:
    """Why the loop runs where the cost rule was not asked (``Run.loop_why``)."""
    if compiled:
        return f"the step loop generated from the problem's symbols ({a.name})"
    if kernel == "python":
        return "asked for: kernel='python'"
    if a.dtype is not float:
        return f"precision {a.name} runs in the Python loop (mpmath)"
    if not kernels.available():
        return "numba is not installed"
    if os.environ.get("TABLEAU_LAB_KERNEL") == "python":
        return "asked for: TABLEAU_LAB_KERNEL=python"
    return "the Python loop"


def integrate(nm: NumericMethod, prob, y0, h, steps: int, *, start: str = "exact", project=(),
              invariants=(), record_every: int | None = None, record_states: bool = False,
              masks=None, problem_name: str = "", progress=None, compensated: bool = True,
              kernel: str = "auto", monitor: float | None = None, solver: str = "auto",
              track_every: int = limits.TRACK_EVERY, predict: bool = True) -> Run:
    """Run ``steps`` steps of size h from y0 (a state vector at the method's precision).

    ``prob`` is a compiled problem (``f``, ``jac`` for implicit methods, ``invariant`` and
    ``gradient`` for projection/records, ``elementary_differentials`` for GLM starts).
    Records every ``record_every`` steps (and the last): time, invariant errors, and states
    if ``record_states``; memory grows with the records only.  The largest |I − I(y₀)| of the
    invariants and projected invariants is also tracked every ``track_every`` steps (default
    ``limits.TRACK_EVERY``; 1 for every step; ``Run.tracked``).  ``compensated=False`` turns the
    Kahan summation of the principal increment off, ``predict=False`` the predicted start of the stage iteration (to
    measure what they buy).  ``solver``: the stage iteration, "auto", "newton" or "fixedpoint"
    (:func:`stage_iteration`).
    ``kernel``: "compiled" runs the step loop compiled (:mod:`kernels`), "python" the same
    loop in Python, "auto" the compiled one when the arithmetic is float64 and the problem is a
    generated one (results agree to round-off), unless the environment variable
    TABLEAU_LAB_KERNEL is "python"; "cost" as "auto", then in float64 the loop predicted to finish
    first (:func:`~.limits.choose_loop`: the Python loop's predicted time against the compile or
    cache load, :func:`~.kernels.compile_state`; its reason in ``Run.loop_why``).  Precision dd
    always runs compiled.
    ``monitor``: a bound on the parasitic components of a GLM's input vector, checked at the
    records; exceeding it raises :class:`ParasiticBoundExceeded` (module docstring).  The
    components and the predicted growth are recorded with or without a bound."""
    a = nm.arith
    if not (isinstance(track_every, int) and track_every >= 1):
        raise ValueError(f"track_every must be a positive integer, not {track_every!r}")
    with a.context():
        y0 = np.array(list(y0), dtype=a.dtype)
        d = len(y0)
        masks = component_masks(prob, d) if masks is None else masks
        h = _step_size(a, h)
        run = Run(nm.name, problem_name, a.name, float(h), steps,
                  start if (nm.r > 1 or nm.starting) else "identity", tuple(project))
        names = tuple(dict.fromkeys(tuple(invariants) + tuple(project)))
        try:
            with np.errstate(over="ignore", invalid="ignore", divide="ignore"):    # refused below, by name
                targets = {k: prob.invariant(k, y0) for k in names}
                _finite_start(nm, prob, y0, targets, a.name)
        except IntegrationError as exc:
            exc.partial = run
            raise
        run.invariant_scales = {k: abs(float(v)) or 1.0 for k, v in targets.items()}
        run.state_scale = (float(a.norm(y0)) if d else 0.0) or 1.0
        run.invariant_errors = {k: [] for k in names}
        pk = kernels.Pack(nm, prob, h, masks, mode=_mode(solver, nm, prob, y0, h, masks), compensated=compensated,
                          predict=predict, project=tuple(project), track=names, targets=targets,
                          index=kernels.invariant_index(prob))
        compiled, switch = _use_kernel(kernel, a, prob), None
        if compiled and kernel == "cost" and a.name == "float64":
            compiled, run.loop_why, switch = _cheaper_loop(nm, prob, pk, steps, d)
        run.loop = {True: "compiled", False: "python", "linked": "linked"}[compiled]
        run.loop_why = run.loop_why or _loop_reason(kernel, a, compiled)
        loop = _loop(compiled, nm, prob, pk)
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

        def settle(out):
            run.nfev, run.newton_iterations = out.nfev, out.sweeps
            run.projection_iterations, run.completed = out.projection_iterations, out.completed
            run.tracked = out.tracked
            run.velocity_evaluations, run.fallbacks = out.nvel, out.fallbacks
            run.compile_seconds = out.compile_seconds
            run.switched(out.switched_at, out.switched_to)
            run.seconds = time.perf_counter() - t0 - run.compile_seconds

        record(0, Y)
        try:
            try:
                with np.errstate(over="ignore", invalid="ignore", divide="ignore"):   # inf/NaN: a status, below
                    out = kernels.drive(loop, pk, Y, steps, every, record=record, progress=progress,
                                        track_every=track_every, switch=switch)
            except BaseException as exc:
                if hasattr(exc, "outcome"):
                    settle(exc.outcome)
                raise
            settle(out)
            _raise_status(out, h, pk.tol, project)
        except KeyboardInterrupt as exc:
            run.even_records()
            exc.partial = run                      # the records so far, for a valid incomplete file
            raise
        except IntegrationError as exc:
            exc.partial = run
            if nm.r > 1 and len(run.parasitic) > 1 and not isinstance(exc, ParasiticBoundExceeded):
                raise _with_parasitic_components(exc, run) from None
            raise
        run.final = principal(out.Y)
    return run


def _step_size(a, h):
    """h at the working precision: an exact step size (1/100) rounded once, here; a float given
    for an mpmath run taken as the decimal it prints as, rounded once."""
    if isinstance(h, int) or is_exact(h):
        return a.number(h)
    if a.dtype is object and not hasattr(h, "_mpf_"):
        from fractions import Fraction

        import mpmath
        q = Fraction(repr(float(h)))
        return mpmath.mpf(q.numerator) / q.denominator
    return h


def _cheaper_loop(nm, prob, pk, steps: int, d: int) -> tuple:
    """(loop, why, switch) for kernel="cost", ``loop`` True (the compiled loop specialised to the
    run), False (the pure loop) or "linked" (the compiled loop shared by every problem,
    :func:`~.kernels.linked_loop`): the loop predicted to finish first (:func:`~.limits.choose_loop`).
    When the specialised loop would need a compile: the linked loop if it is built (its problem's
    entry points compile in about ``limits.LINKED_PROBLEM_SECONDS``); else a run long enough
    (:func:`.background.worth`) starts in Python while its loop compiles in the background, and
    ``switch`` (for :func:`~.kernels.drive`) moves it to the compiled loop once that is ready."""
    shape = kernels.run_shape(pk)
    python, load = limits.python_step_seconds(nm.s, nm.r, d, nm.explicit, len(pk.proj)), limits.load_seconds()
    state = kernels.compile_state(prob.problem, "f64", shape, disk=False)
    if state is None and steps * python > load:
        state = kernels.compile_state(prob.problem, "f64", shape)
        if state == "cold":
            quick = _without_compile(nm, prob, pk, steps, d, python * steps, shape, load)
            if quick is not None:
                return quick
    compiled, why = limits.choose_loop(
        steps, python, state or (lambda: kernels.compile_state(prob.problem, "f64", shape)), load)
    return compiled, why, None


def _without_compile(nm, prob, pk, steps: int, d: int, seconds: float, shape, load: float):
    """The start of a run whose specialised loop is not compiled and whose Python loop would take
    longer (``seconds``) than a cache ``load`` (:func:`_cheaper_loop`): the linked loop when built
    and worth its problem's entry points; else, when worth it, the Python loop while the linked
    loop of its stage iteration and projection builds in the background (the specialised loop
    when there is no shape: TABLEAU_LAB_SPECIALISE=0), moving to it once built; else None (the
    cost rule).  A run long enough to repay its specialised loop's compile against the linked
    loop (:func:`~.limits.specialised_repays`) also has that compiled in the background, and moves
    to it once ready."""
    if shape is not None and kernels.linked_state(shape) != "cold" and (
            seconds > load + limits.LINKED_PROBLEM_SECONDS        # + the problem's entry points
            or kernels.entries_state(prob.problem, shape, len(pk.c), len(pk.track) > 0) != "cold"):
        return "linked", (f"the compiled loop shared by every problem: {steps} steps predicted at {seconds:.2g} s "
                          "in Python, the specialised loop not compiled"), _later(prob, pk, nm, d, seconds, shape, [])
    if not (background.worth(seconds) and background.possible()):
        return None
    if shape is not None:                  # the shared loop: built once for every later problem and shape
        c = background.start_shared(shape, _task_args(prob, pk, nm, d))
        now = [(c, lambda: kernels.linked_loop(prob.problem, shape))]
        what = "the compiled loop shared by every problem"
    else:
        now, what = _specialised(prob, pk, nm, d, shape), "the compiled loop"
    why = (f"the Python loop, then {what} once compiled in the background ({steps} steps predicted at "
           f"{seconds:.2g} s in Python)")
    return False, why, _later(prob, pk, nm, d, seconds, shape, now)


def _task_args(prob, pk, nm, d: int) -> tuple:
    """The arguments of a loop's ``run`` with no step, of this run's types (a background compile's task)."""
    return kernels.LoopState(kernels.pure_loop(prob, "float64"), pk, np.zeros((nm.r, d)), 1, 1).args(0, 0)


def _specialised(prob, pk, nm, d: int, shape) -> list:
    """[(the background compile of the loop specialised to the run, the loop once ready)]."""
    c = background.start(prob.problem, "f64", shape, _task_args(prob, pk, nm, d))
    return [(c, lambda: kernels.compiled_loop(prob.problem, "f64", shape))]


def _later(prob, pk, nm, d: int, seconds: float, shape, now: list):
    """drive's ``switch`` to the loops compiling in the background for this run: ``now`` (the
    linked loop being built, or the specialised one), preceded by the specialised loop when the run
    is long enough to repay its compile against the linked loop (queued behind ``now``); None
    when there are none."""
    if shape is not None and limits.specialised_repays(seconds) and background.possible():
        now = _specialised(prob, pk, nm, d, shape) + now
    return background.switch_when_ready(*now) if now else None


def _raise_status(out, h, tol, project) -> None:
    """The loop's failure status (:mod:`stepcore`) as the error naming the step and time."""
    n, t = out.step, out.step * h
    if out.status == 1:
        raise stages_failed(n, t, h, out.last_correction, tol)
    if out.status == 2:
        raise not_finite(n, t)
    if out.status == 3:
        raise projection_failed(project, n, t, out.projection_residual)


def _with_parasitic_components(exc, run) -> IntegrationError:
    """``exc`` with the sizes of a GLM's non-principal input components (smallest and last
    recorded): a failure that follows their growth is parasitism."""
    k = int(np.argmin(run.parasitic))
    growing = " (growing: parasitism?)" if run.parasitic[-1] > 10 * run.parasitic[k] else ""
    err = IntegrationError(f"{exc}. Non-principal input components max|y^[n]_k|, k ≥ 2: "
                           f"{run.parasitic[k]:.2e} at t = {run.times[k]:.4g}, "
                           f"{run.parasitic[-1]:.2e} at t = {run.times[-1]:.4g}" + growing)
    err.partial = run
    return err


def step(nm: NumericMethod, prob, Y, h, *, masks=None, solver: str = "newton"):
    """One step of the pure loop from the input vector Y (r × d) with step h: y^[1] (r × d).
    ``prob`` needs only ``f`` and ``jac``.  For checks of the step map itself (symmetry)."""
    a = nm.arith
    with a.context():
        Y = np.array(Y, dtype=a.dtype)
        d = Y.shape[1]
        masks = component_masks(prob, d) if masks is None else masks
        pk = kernels.Pack(nm, prob, h, masks, mode=_mode(solver, nm, prob, Y[0], h, masks), compensated=False)
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):   # inf/NaN: a status, below
            out = kernels.drive(kernels.pure_loop(prob, a.name), pk, Y, 1, 1, record=lambda n, Y: None)
        if out.status:
            raise IntegrationError(f"one step of size {float(h):.6g}: the loop stopped with status {out.status}")
        return out.Y


def _loop(compiled, nm, prob, pk):
    """The compiled module (specialised to the run: :func:`kernels.run_shape`; "linked": the one
    shared by every problem, :func:`kernels.linked_loop`) or the pure loop."""
    a = nm.arith
    if compiled == "linked":
        return kernels.linked_loop(prob.problem, kernels.run_shape(pk))
    if compiled:
        return kernels.compiled_loop(prob.problem, "dd" if a.name == "dd" else "f64", kernels.run_shape(pk))
    return kernels.pure_loop(prob, a.name)
