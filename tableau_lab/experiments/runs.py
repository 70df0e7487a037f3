r"""Quick runs and convergence studies: a method file, a problem, step sizes → numbers.

``quick_run`` is what ``tableau-lab run --method FILE --problem NAME ...`` prints; ``convergence``
measures the global error at a final time against the problem's high-precision reference for a
range of step sizes and fits the order by least squares on the log–log points that lie above
the round-off plateau.  A run that an instability destroys is kept as evidence (the step, the
time, the message), never silently dropped.

>>> r = quick_run("methods/gauss2.json", "harmonic", h=0.1, steps=100)
>>> r["steps"], r["max_invariant_error"]["H"] < 1e-14
(100, True)
"""
from __future__ import annotations

import dataclasses
import functools
from dataclasses import dataclass, field
from math import isfinite as math_isfinite
from typing import NamedTuple

import mpmath
import numpy as np
import sympy as sp

from ..budget import DEFAULT_SECONDS, computing, time_limit
from ..errors import InputError
from ..exact.tableau_json import TableauError, load
from ..inputs import MAX_STEPS
from ..numeric.arith import arith, is_exact
from ..numeric.codegen import compile_problem, reference
from ..numeric.export import to_numeric
from ..numeric.integrate import IntegrationError, integrate
from ..numeric.problems import get_problem
from .executor import executor
from .job import RunJob

__all__ = ["quick_run", "prepare_quick", "convergence", "Convergence", "fit_order", "roundoff", "step_size",
           "step_count", "final_time", "generate", "prepare_run", "PreparedRun"]


def step_size(h, what: str = "h"):
    """A step size as the API and the command line take it: an exact string ("1/100"; "0.01" is
    1/100) read by the project's number grammar (:func:`~tableau_lab.exact.grammar.parse_number`),
    an integer, a sympy number, or a float; refused (InputError naming ``what``) unless it is a
    positive real number within float64's range (every run's time grid is float64).

    >>> step_size("1/100"), step_size("0.01"), step_size(0.1)
    (1/100, 1/100, 0.1)
    >>> step_size("-1/100", "--h")
    Traceback (most recent call last):
    ...
    tableau_lab.errors.InputError: --h -1/100: the step size must be positive
    """
    import math

    from ..exact.grammar import EntryError, parse_number
    text = h
    if isinstance(h, str):
        try:
            h = parse_number(h)
        except EntryError as exc:
            raise InputError(f"{what}: {exc}") from None
    elif isinstance(h, bool) or not (isinstance(h, (int, float)) or is_exact(h)):
        raise InputError(f"{what}: {str(h)[:60]!r} is not a step size: give a positive number, e.g. \"1/100\"")
    if is_exact(h):
        if not (h.is_real and h > 0):
            raise InputError(f"{what} {text}: the step size must be positive")
        hf = float(h)
    else:
        hf = float(h)
        if not hf > 0:
            raise InputError(f"{what} {text}: the step size must be positive")
    if not (math.isfinite(hf) and hf > 0):
        raise InputError(f"{what} {text}: rounds to {hf} in float64; give a step size between 1e-300 and 1e300")
    return h


def final_time(T, what: str | None = None):
    """A final time: a positive real number within float64's range (InputError naming
    ``what``, by default "T = value").

    >>> final_time(0)
    Traceback (most recent call last):
    ...
    tableau_lab.errors.InputError: T = 0: the final time must be a positive number within float64's range
    """
    try:
        ok = bool(T > 0) and math_isfinite(float(T))
    except (TypeError, ValueError, OverflowError):
        ok = False
    if not ok:
        raise InputError(f"{what or f'T = {str(T)[:40]}'}: the final time must be a positive number within "
                         "float64's range")
    return T


def step_count(steps, what: str = "steps") -> int:
    """A number of steps: an integer from 1 to ``inputs.MAX_STEPS`` (InputError naming ``what``)."""
    if isinstance(steps, bool) or not isinstance(steps, int) or not 1 <= steps <= MAX_STEPS:
        raise InputError(f"{what}: {str(steps)[:40]} is not a number of steps (an integer from 1 to {MAX_STEPS})")
    return steps


def compiled(problem, precision: str):
    """The problem's generated code for the arithmetic of ``precision``."""
    a = arith(precision)
    return compile_problem(problem, a.backend, None if a.backend == "numpy" else a.dps)


class PreparedRun(NamedTuple):
    """What a run needs, built once (:func:`prepare_run`)."""
    method: object          # the exact method (exact/methods.py)
    problem: object         # the problem with its overrides (numeric/problems.py)
    compiled: object        # its generated code for the precision (numeric/codegen.py)
    numeric: object         # the method rounded to the precision (numeric/export.py)


def prepare_run(method, problem, precision: str, overrides=None) -> PreparedRun:
    """The exact method (a file, a name or a method), the problem (a name, with ``overrides`` of
    its parameters or initial values), its compiled code and the numeric method for
    ``precision`` ("float64", "dd", "mp:DIGITS"): what every run, benchmark and convergence study
    starts from.  A method with free parameters is refused first (TableauError naming its file).

    >>> prep = prepare_run("gauss2", "pendulum", "float64")
    >>> prep.method.name, prep.problem.name, prep.numeric.s
    ('Gauss–Legendre, 2 stages', 'pendulum', 2)
    """
    m = load(method) if not hasattr(method, "kind") else method
    if m.parameters:
        raise TableauError(str(method) if not hasattr(method, "kind") else m.name,
                           f"free parameters {', '.join(map(str, m.parameters))}: a run needs numbers; "
                           "solve for them first (tableau-lab solve)")
    P = get_problem(problem, **(overrides or {}))
    return PreparedRun(m, P, compiled(P, precision), to_numeric(m, precision))


def quick_run(method, problem, h, steps, *, precision="float64", project=(), start="exact", overrides=None,
              monitor=None):
    """One run; the result as a JSON-ready dict (final state through the finishing method).
    ``monitor``: the parasitism monitor's bound (``integrate``); GLMs report their largest
    parasitic component per ζ."""
    return prepare_quick(method, problem, h, steps, precision=precision, project=project, start=start,
                         overrides=overrides, monitor=monitor).execute()


def prepare_quick(method, problem, h, steps, *, precision="float64", project=(), start="exact", overrides=None,
                  monitor=None, frozen=False) -> RunJob:
    """The exact stage of :func:`quick_run`: the method read and rounded, the problem's code
    generated, the step rounded once.  ``frozen``: the method and problem as data that runs in a
    process without sympy (``experiments/job.py``): only the code this run calls (f, f′ for
    implicit methods and GLMs, the invariants, the gradients projected on, the derivatives of
    the starting and finishing series) and the compiled loop's file."""
    h, steps = step_size(h), step_count(steps)
    m, P, cp, nm = prepare_run(method, problem, precision, overrides)
    project = P.check_projection(project)
    invs, a = tuple(P.invariants), nm.arith
    if isinstance(h, int) or is_exact(h):
        with a.context():
            h = a.number(h)                       # rounded once, here: the job carries no sympy number
    if not frozen:
        generate(cp, nm, invs, project)
    if frozen:
        from ..analysis.trees import order as tree_order
        from ..numeric.frozen import freeze
        p = max((tree_order(t) for t in (*nm.starting, *nm.finishing)), default=0)
        cp = freeze(cp, invariants=invs, gradients=tuple(project), jac=not nm.explicit or nm.r > 1,
                    derivatives=p, kernels=("dd" if precision == "dd" else "f64",))
        nm = dataclasses.replace(nm, exact=None)
    return RunJob(nm, cp, h, steps, start, tuple(project), invs, monitor, precision, m.name, P.name,
                  len(P.q) if P.kind == "hamiltonian" else None)


def generate(cp, nm, invariants=(), project=()) -> None:
    """Generate the code a run of ``nm`` on the compiled problem ``cp`` calls — f, f′ (implicit
    methods, GLMs), the invariants, the gradients projected on, the derivatives of a starting
    or finishing series — now, inside the caller's time budget, not lazily at the run's first
    step (a user problem's Jacobian can take minutes to generate)."""
    import numpy as np

    from ..analysis.trees import order as tree_order
    y = cp.y0
    with np.errstate(all="ignore"), nm.arith.context():     # values are checked by the run (step 0)
        cp.f(y)
        if not nm.explicit or nm.r > 1:
            cp.jac(y)
        for k in tuple(invariants) + tuple(project):
            cp.invariant(k, y)
        for k in project:
            cp.gradient(k, y)
        p = max((tree_order(t) for t in (*nm.starting, *nm.finishing)), default=0)
        if p > 1:
            cp.elementary_differentials(p)(y)


def fit_order(hs, errs, floor: float):
    """Least-squares slope of log err against log h over the points above 100·floor (the
    round-off plateau); None with fewer than three such points."""
    pts = [(np.log(h), np.log(e)) for h, e in zip(hs, errs, strict=False) if e is not None and e > 100 * floor]
    if len(pts) < 3:
        return None
    x, y = np.array(pts).T
    return float(np.polyfit(x, y, 1)[0])


@dataclass
class Convergence:
    method: str
    problem: str
    precision: str
    T: float
    order: int                    # the computed order of the method (with this start)
    hs: list = field(default_factory=list)
    errors: list = field(default_factory=list)   # None where the run failed
    slope: float | None = None
    failures: list = field(default_factory=list)  # (h, message)
    nfev: list = field(default_factory=list)
    growth: list = field(default_factory=list)    # GLMs: max/min of the non-principal input components

    @property
    def verdict(self) -> str:
        if self.slope is not None and abs(self.slope - self.order) <= 0.2:
            return "order confirmed"
        last_failed = bool(self.errors) and self.errors[-1] is None
        grew = bool(self.growth) and self.growth[-1] is not None and self.growth[-1] > 1e3
        if self.failures and (last_failed or grew):
            h, msg = self.failures[-1]             # the smallest step size that still failed
            return f"destroyed by an instability (h = {h:.3g}): " + msg
        if grew:
            return (f"destroyed by an instability: the non-principal input components grew by a factor "
                    f"{self.growth[-1]:.2g} in the run with the smallest h (parasitism)")
        note = f"; runs failed for h ≥ {min(h for h, _ in self.failures):.3g}" if self.failures else ""
        return f"order NOT confirmed (pre-asymptotic up to n = {int(round(self.T / min(self.hs)))}{note})"

    def to_json(self):
        return {"method": self.method, "problem": self.problem, "precision": self.precision, "T": self.T,
                "order": self.order, "h": self.hs, "error": self.errors, "slope": self.slope,
                "verdict": self.verdict, "failures": [{"h": h, "message": msg} for h, msg in self.failures],
                "nfev": self.nfev, "parasitic_growth": self.growth}


def convergence(method, problem, T=10.0, steps=None, *, precision="float64", start="exact", overrides=None,
                ref_dps: int = 40, n0: int = 50, max_steps: int = 1 << 15, scheduler=None,
                workers: int | None = None, timeout: float | None = DEFAULT_SECONDS) -> Convergence:
    """Global error at T against the problem's reference solution.  With ``steps`` given, those
    step counts; otherwise n = n0, 2n0, 4n0, … until three successive local slopes agree to 0.1
    (the asymptotic regime), the error reaches the round-off plateau, or ``max_steps``.  Runs that
    fail (an instability, a stage solve that diverges) are recorded with their message; the slope
    is fitted by least squares on the last points above the plateau, at most four (those
    whose three local slopes agree when the study settled).

    The runs go through :func:`~tableau_lab.experiments.executor.executor` (``scheduler``,
    ``workers``: a local process pool by default, "serial", a Dask scheduler's address, or an
    open executor); the result is the same, bit for bit, whichever ran them.  ``T`` must be a
    positive number (InputError); the reference solution is computed within the time budget
    ``timeout`` (seconds; BudgetError), as the exact commands' work."""
    T = final_time(T)
    m, P, _, nm = prepare_run(method, problem, precision, overrides)
    a = nm.arith
    with time_limit(timeout), computing(f"the reference solution of {P.name} at T = {float(T):g}"):
        ref = reference(P, T, max(ref_dps, a.dps + 8))
    out = Convergence(m.name, P.name, precision, T, nm.order if start == "exact" else nm.order_identity)
    Texact = sp.nsimplify(T)
    with a.context():                          # the reference at the working precision, once
        ref = [a.number(sp.Float(str(r), a.dps + 8)) for r in ref]
    task = functools.partial(convergence_run, nm, P, Texact, start)
    with executor(scheduler, workers) as ex:
        def runs(ns):
            return ex.map(task, ns, describe=lambda n: f"n = {n}, h = {float(T) / n:.3g}", desc=m.name)
        if steps:
            for n, point in zip(steps, runs(list(steps)), strict=False):
                _add_point(out, n, point, ref)
        n = n0
        while not steps and n <= max_steps:
            # as many step counts at once as the executor runs; those past the stopping point
            # are dropped, so every executor gives the serial loop's result
            batch = []
            while len(batch) < ex.workers and n <= max_steps:
                batch.append(n)
                n *= 2
            if any(_add_point(out, k, point, ref) and _settled(out.hs, out.errors, a.eps)
                   for k, point in zip(batch, runs(batch), strict=False)):
                break
    # adaptive: the last four points, whose three local slopes agree when the study settled
    k = 0 if steps else -4                  # an adaptive study fits its last four (settled) points
    out.slope = fit_order(out.hs[k:], out.errors[k:], a.eps)
    return out


class ConvergencePoint(NamedTuple):
    """What one run of a convergence study hands back, whichever executor ran it."""
    final: object               # the finished state at T (working precision); None if the run failed
    nfev: int | None
    parasitic: list             # GLMs: max |y^[n]_k|, k ≥ 2, at the records
    failure: str | None         # the IntegrationError's message


def convergence_run(nm, problem, T, start, n) -> ConvergencePoint:
    """One run of a convergence study: n steps of size T/n (T exact) of the numeric method
    ``nm`` on ``problem`` (a Problem).  The executor's task: a module-level function of
    picklable arguments; the problem's code is generated once per worker process (cached)."""
    a = nm.arith
    cp = compiled(problem, a.name)
    try:
        run = integrate(nm, cp, cp.y0, a.number(T / n), n, start=start)
    except IntegrationError as exc:
        return ConvergencePoint(None, None, [], str(exc))
    return ConvergencePoint(run.final, run.nfev, list(run.parasitic), None)


def _add_point(out: Convergence, n: int, point: ConvergencePoint, ref) -> bool:
    """Append the run with n steps to ``out`` (the error against ``ref`` at the working
    precision); True when the run succeeded."""
    h = float(out.T) / n
    out.hs.append(h)
    if point.failure is not None:
        out.errors.append(None)
        out.failures.append((h, point.failure))
        out.nfev.append(None)
        out.growth.append(None)
        return False
    a = arith(out.precision)
    with a.context():
        out.errors.append(float(max(abs(x - r) for x, r in zip(point.final, ref, strict=False))))
    out.nfev.append(point.nfev)
    par = [x for x in point.parasitic if x > 0]
    out.growth.append(float(max(par) / min(par)) if len(par) > 1 else None)
    return True


def _settled(hs, errs, floor) -> bool:
    """Three successive local slopes within 0.1 of each other, or the round-off plateau reached."""
    pts = [(np.log(h), np.log(e)) for h, e in zip(hs, errs, strict=False) if e is not None]
    if errs and errs[-1] is not None and errs[-1] <= 100 * floor:
        return True
    if len(pts) < 4:
        return False
    sl = [(pts[i][1] - pts[i - 1][1]) / (pts[i][0] - pts[i - 1][0]) for i in range(len(pts) - 3, len(pts))]
    return max(sl) - min(sl) < 0.1


def roundoff(method, problem, h, steps, *, starts=4, every=None, dps: int = 32, overrides=None, seed: int = 1):
    """Round-off separated from method error: the same runs (same h, same method) in float64,
    with and without compensated summation, and at ``dps`` digits; the difference float64 −
    mpmath is the round-off alone.  Averaged (root mean square) over ``starts`` initial values
    near the problem's (relative perturbations of 10 %), recorded every ``every`` steps.  Returns
    {"n": [...], "compensated": [...], "plain": [...], "slope_compensated", "slope_plain"}: the
    growth exponents fitted on log-log data (Brouwer's law predicts 1/2 for a random walk)."""
    m, P, cp64, nm64 = prepare_run(method, problem, "float64", overrides)
    # the reference runs the float64 method exactly as represented (its rounded coefficients,
    # step size and initial value, converted exactly) at dps digits: the difference is the
    # arithmetic round-off alone, not the representation of 1/6 or 0.01 in binary
    nm_mp, cp_mp = _exactly(nm64, arith(f"mp:{dps}")), compiled(P, f"mp:{dps}")
    every = every or max(1, steps // 50)
    rng = np.random.default_rng(seed)
    h64 = float(sp.nsimplify(h))
    acc = {"compensated": 0.0, "plain": 0.0}
    for _ in range(starts):
        factors = [sp.Rational(int(x), 1000) for x in 1000 + rng.integers(-100, 101, size=P.dimension)]
        # the problem's exact start (parameters substituted: Kepler's 1 − e), perturbed exactly, rounded once
        y064 = nm64.arith.array([v * f for v, f in zip(P.initial_state(), factors, strict=False)])
        with nm_mp.arith.context():
            ref = integrate(nm_mp, cp_mp, [mpmath.mpf(v) for v in y064], mpmath.mpf(h64), steps,
                            record_every=every, record_states=True)
        for key, comp in (("compensated", True), ("plain", False)):
            run = integrate(nm64, cp64, y064, h64, steps, record_every=every, record_states=True, compensated=comp)
            with mpmath.workdps(dps):           # the difference is taken at the reference's precision
                acc[key] = acc[key] + np.array([float(sum((mpmath.mpf(x) - y) ** 2 for x, y in zip(a, b, strict=False)))
                                                for a, b in zip(run.values, ref.values, strict=False)])
    n = np.arange(len(acc["plain"])) * every
    out = {"n": n.tolist()}
    for key in acc:
        rms = np.sqrt(acc[key] / starts)
        out[key] = rms.tolist()
        keep = (n > 0) & (rms > 0)
        out[f"slope_{key}"] = float(np.polyfit(np.log(n[keep]), np.log(rms[keep]), 1)[0]) if keep.sum() > 2 else None
    return out


def _exactly(nm64, a):
    """nm64 in the arithmetic ``a``: every float64 coefficient converted exactly (no new
    rounding from the exact tableau, no second order analysis)."""
    with a.context():
        def conv(X):                             # float64 array -> array of mpf, each value exactly
            return np.vectorize(lambda x: mpmath.mpf(float(x)), otypes=[object])(X)

        return dataclasses.replace(
            nm64, arith=a, Aq=conv(nm64.Aq), Ap=conv(nm64.Ap), U=conv(nm64.U), Bq=conv(nm64.Bq), Bp=conv(nm64.Bp),
            V=conv(nm64.V), c=conv(nm64.c), u=conv(nm64.u), w=conv(nm64.w),
            starting={t: conv(v) for t, v in nm64.starting.items()},
            finishing={t: mpmath.mpf(float(v)) for t, v in nm64.finishing.items()})
