r"""A compiled adaptive peer for the work–precision diagrams (issue 19, item 6): Hairer's DOP853
(explicit Runge–Kutta of order 8 with step-size control; Hairer, Nørsett & Wanner, *Solving
Ordinary Differential Equations I*, 2nd ed., Sec. II.10) as compiled by the numbalsoda package,
called with the problem's own numba-compiled f through a C function pointer — no Python in the
step loop, as in our compiled loop.  scipy's ``solve_ivp(method="DOP853")`` runs the same
algorithm but steps in Python; this peer is the fair one for CPU time.

numbalsoda is optional (``pip install -e ".[bench]"``; building it needs a Fortran compiler,
e.g. ``apt-get install gfortran``).  Without it a point reports ``failed`` with that hint.

The f-evaluations are counted by the right-hand side itself (a counter in its data array).
The energy error is the largest |I(y(tₖ)) − I(y₀)| over ``SAMPLES_PER_UNIT``·T dense-output
points tₖ (numbalsoda returns the solution only at requested times, not at its accepted steps),
from a second, untimed run with dense output (which costs DOP853 three more evaluations a step):
the timed run asks for the final state only.
"""
from __future__ import annotations

import functools
import time

import numpy as np

__all__ = ["PEER", "SAMPLES_PER_UNIT", "available", "dop853_point", "max_invariant_error"]

PEER = "DOP853 (compiled)"
SAMPLES_PER_UNIT = 20          # dense-output points per unit of time at which the energy error is read
MAX_STEPS = 10 ** 8


def available() -> bool:
    try:
        import numbalsoda  # noqa: F401 - imported, not looked up: a numbalsoda whose library fails to load is missing too
    except ImportError:
        return False
    return True


@functools.lru_cache(maxsize=None)
def _rhs(f_, d: int, nc: int):
    """A C callback (t, u, du, p) of numbalsoda's signature around the compiled f_(y, c, out, i):
    p[0] counts the calls, p[1:] are the problem's constants.  Compiled once per problem and
    process (the sweep's tolerances of one worker share it)."""
    import numba
    from numbalsoda import lsoda_sig

    @numba.cfunc(lsoda_sig)
    def rhs(t, u, du, p):
        y = numba.carray(u, (d,))
        out = numba.carray(du, (1, d))
        data = numba.carray(p, (nc + 1,))
        data[0] += 1.0
        f_(y, data[1:], out, 0)
    return rhs


def max_invariant_error(mod, invariant, c, y0, states) -> float:
    """max |I(y) − I(y₀)| over the rows of ``states``, I evaluated by the compiled problem
    module's ``inv_`` (the energy error of this peer and of scipy's, after their timed runs)."""
    k, val = mod.invariant_index[invariant], np.empty(1)
    c = np.asarray(c, dtype=float)

    def inv(y):
        mod.inv_(k, np.ascontiguousarray(y), c, val)
        return val[0]
    I0 = inv(y0)
    return float(max((abs(inv(y) - I0) for y in states), default=0.0))


def dop853_point(problem, T, rtol, atol_factor, invariant):
    """One DOP853 run (numbalsoda) on [0, T]: CPU seconds, f-evaluations, final state and the
    largest |I − I₀| over the dense-output samples; ``failed`` when numbalsoda is missing or the
    integration fails."""
    if not available():
        return {"rtol": rtol, "failed": "numbalsoda is not installed (pip install -e \".[bench]\"; it needs gfortran)"}
    from numbalsoda import dop853

    from ..numeric.codegen import compile_problem
    from ..numeric.kernels import compiled_loop
    cp = compile_problem(problem)
    mod = compiled_loop(cp.problem)
    c = [float(v) for v in cp.constants]
    y0 = np.array(cp.y0, dtype=float)
    rhs = _rhs(mod.f_, len(y0), len(c))
    data = np.array([0.0, *c])
    dop853(rhs.address, y0, np.array([0.0, 1e-3]), data=data, rtol=rtol, atol=rtol * atol_factor,
           mxstep=MAX_STEPS)                                                   # compile, untimed
    warm = int(data[0])
    t0 = time.process_time()                 # the timed run: the final state only (no dense output)
    usol, success = dop853(rhs.address, y0, np.array([0.0, float(T)]), data=data, rtol=rtol,
                           atol=rtol * atol_factor, mxstep=MAX_STEPS)
    cpu = time.process_time() - t0
    nfev = int(data[0]) - warm
    if not success or not np.all(np.isfinite(usol[-1])):
        return {"rtol": rtol, "failed": f"DOP853 (numbalsoda) failed before t = {float(T):g}"}
    final = usol[-1].tolist()
    # the same run again, untimed, with dense output at the samples (it costs 3 more f per step)
    t_eval = np.linspace(0.0, float(T), int(SAMPLES_PER_UNIT * float(T)) + 1)
    usol, _ = dop853(rhs.address, y0, t_eval, data=data, rtol=rtol, atol=rtol * atol_factor, mxstep=MAX_STEPS)
    err = max_invariant_error(mod, invariant, c, y0, usol)
    return {"rtol": rtol, "cpu": cpu, "nfev": nfev, "final": final,
            "invariant_error": float(err), "samples": int(t_eval.size)}
