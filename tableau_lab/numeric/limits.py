r"""Every tolerance, iteration cap and switch of the step loop, named once, and the rule that
chooses the stage iteration.  The step core (:mod:`stepcore`) reads these names in every
precision (compiled modules import them: numba takes them as compile-time constants); the
driver (:mod:`kernels`) lays out the flag and counter arrays with the indices below.

The stage iteration (:func:`choose_iteration`; Hairer, Lubich & Wanner, *Geometric Numerical
Integration*, 2nd ed., Sec. VIII.6): the cheaper of fixed point and simplified Newton by a cost
model in arithmetic operations (:func:`iteration_costs`).  With κ = h·‖A_q‖∞·ρ(f′(y₀)), fixed
point contracts by about κ a sweep (by κ² on the q stages of a separable problem, ``SPLIT``: the
contraction is of order (h·‖A‖)²‖∂f_p/∂q‖‖∂f_q/∂p‖, as in Hairer's GNI_IRK2 for q″ = f(q)) and
needs about 1 + ``START_GAP``/ln(1/κ) sweeps of s f-evaluations from the predicted start (none
if that exceeds ``STAGE_SWEEPS``: it would not converge within the cap); simplified Newton
needs a Jacobian, the LU of I − hA ⊗ f′ (s·d, or s blocks of d for a diagonally implicit
method) and about ``NEWTON_SWEEPS`` sweeps, each with a solve.  ``START_GAP`` and
``NEWTON_SWEEPS`` are measured (``python benchmarks/stage_cost.py``, docs/speed.md).  The rule
was a threshold, κ < 0.1: Gauss 3 on Kepler went to Newton at h = 1/50 and cost 6× the step
of h = 1/100 for the same f-evaluations (issue 29, item 12).  A step whose fixed-point
iteration fails is redone by simplified Newton; after ``SWITCH_AFTER`` such steps the run goes
on with Newton (the problem has become stiff along the solution).

>>> choose_iteration("auto", explicit=False, separable=True, contraction=0.2, s=3, d=4, f_ops=28)
2
>>> choose_iteration("auto", explicit=False, separable=True, contraction=2.0, s=2, d=12, f_ops=89) == NEWTON
True
"""
from __future__ import annotations

import math

# -- stage iteration modes (flags[F_MODE]) ---------------------------------------------------
NEWTON = 0          # simplified Newton: one Jacobian (at the first stage input) and one LU per step
FIXED = 1           # fixed point on all components (Newton with M = I)
SPLIT = 2           # fixed point on the q stages of a separable problem (GNI_IRK2's iteration)
FULL = 3            # full Newton: Jacobians at the stages, refreshed every sweep (fallback only)
EXPLICIT = 4        # an explicit method's stages in order (a compiled loop's specialisation, not a flag value)
ANY = -1            # a loop not specialised: the flags decide at run time

# -- caps and tolerances ------------------------------------------------------------------------
STAGE_SWEEPS = 60           # sweeps of one attempt of simplified Newton / fixed point
FULL_NEWTON_SWEEPS = 30     # sweeps of full Newton (the first fallback)
RESCUE_SWEEPS = 200         # sweeps of the last fallback: fixed point on the stage values
DIVERGE_AFTER = 3           # sweeps after which a growing correction counts as divergence
STALL_THETA = 0.9           # contraction rate at which a sweep no longer counts as progress
ROUNDOFF_FLOOR = 1000.0     # attainable accuracy, in units of eps × the size of the values
HISTORY = 6                 # steps of stage derivatives kept to extrapolate the next step's start
# extrapolation in n through the last HISTORY values: Σₘ (−1)^(m+1) C(HISTORY, m) F⁽ⁿ⁻ᵐ⁾, m = 1 … HISTORY
HISTORY_WEIGHTS = tuple(float((-1) ** (m + 1) * math.comb(HISTORY, m)) for m in range(1, HISTORY + 1))
SPLIT_TOL_ULPS = 1.0        # the q-stage iteration stops when its correction is this many ulps of q
SWITCH_AFTER = 3            # failed fixed-point steps after which the run switches to Newton
# the stage-iteration cost model (iteration_costs), measured by benchmarks/stage_cost.py:
START_GAP = 20.0            # ln(error of the predicted start / tolerance): sweeps ≈ 1 + START_GAP/ln(1/rate)
NEWTON_SWEEPS = 3.0         # sweeps of simplified Newton per step

PROJECTION_SWEEPS = 50      # Newton sweeps on the multipliers
PROJECTION_STALL = 0.5      # corrections shrinking by less than this count as stalled …
PROJECTION_ROUNDOFF = 1000.0    # … once the residual is below this many eps
PROJECTION_ACCEPT = 1e4     # after the last sweep, a residual below this many eps is round-off

DEGRADED = 1e-2            # a run that ends with an invariant error, or a parasitic component, this large relative
                           # to |I(y0)| (or to max |y0_i|) failed in substance: "degraded" (integrate.Run.degraded)
HUGE = 1e300               # beyond this: overflow at every precision (mpmath has none of its own; results are float64)
TRACK_EVERY = 1             # default stride of the invariant tracking: every step (its cost: docs/speed.md)
QUICK_RUN_RECORDS = 100     # records of a quick run (tableau-lab run): its max |I − I(0)| is tracked at every step
                            # in the loop; a record adds the finished output's and the parasitic components
INLINE_LINEAR_ALGEBRA = 16  # s·d up to which a compiled loop inlines (unrolls) the Newton matrix's LU
INLINE_PROBLEM_DIMENSION = 12   # d up to which f (and the q-, p-rates) are inlined into the loop
CHUNK = 1 << 16             # steps per call of a compiled loop (records, progress, Ctrl-C between)
PURE_CHUNK = 256            # steps per call of the pure (Python) loop

# -- the loop chosen by predicted cost (kernel="cost": integrate() from Python; choose_loop) -------
# measured by `python benchmarks/loop_choice.py` on this 2-core machine (docs/speed.md, "Which loop"):
PYTHON_STAGE_SECONDS = 5e-6     # one stage of an explicit method in the pure float64 loop: this …
PYTHON_COMPONENT_SECONDS = 3e-6     # … plus this per state component (RK4: 27-40 µs/step at d = 2, 43-111 at d = 4)
PYTHON_IMPLICIT_FACTOR = 5.0    # an implicit stage (its share of the stage iteration's sweeps) in explicit stages
PYTHON_PROJECTION_FACTOR = 2.0  # a projected invariant, a step, in explicit stages (measured 0.8-2.1: docs/speed.md)
COMPILE_COLD_SECONDS = 8.0      # numba's first compile of a float64 loop and its problem module, empty cache (3.2-11 s)
COMPILE_CACHED_SECONDS = 0.5    # the same loaded from numba's disk cache (kernels.compile_state "cached"; 0.2-0.5 s)
NUMBA_START_SECONDS = 0.6      # a process's first: importing numba (0.3 s) and its target's set-up at the first load
BACKGROUND_AFTER_SECONDS = 2.0  # a run predicted longer in Python compiles its loop in the background (background.py)
LINKED_PROBLEM_SECONDS = 1.0    # a problem's entry points for the linked loop, compiled (kernels.linked_loop: ~1 s)
BACKGROUND_COMPILES = 1         # background compiles at a time (one core for the run, one for numba)
LINKED_SAVED_FRACTION = 1 / 500    # of a run's predicted Python time, what the specialised loop saves against
                                   # the linked one (linked: Python/330-800 a step, specialised 2.2-3.2× cheaper:
                                   # 1/1450-1/480; docs/speed.md)
COMPILE_NOTICE_SECONDS = 2.0    # a first call whose compile state is not known is announced on a terminal after this

# -- layout of the loop's flag and counter arrays -------------------------------------------------
F_EXPLICIT, F_HAS_E, F_HAS_INV, F_COMPENSATE, F_NHIST, F_MODE, F_HAS_JAC, F_HPOS, F_PREDICT, F_LOWER = range(10)
N_FLAGS = 10                # F_LOWER: A lower triangular (diagonally implicit): Newton's matrix block by block
S_NFEV, S_SWEEPS, S_PROJ, S_NREC, S_STEP, S_PROJ_RES, S_NVEL, S_LAST, S_FALLBACKS, S_DONE = range(10)
N_STATS = 10                # S_STEP: the step under way; S_DONE: the last step finished (a Ctrl-C keeps up to it)
MISFIT = 5                  # the loop's status when its arrays do not fit its shape (stepcore.fits)

__all__ = [name for name in list(globals()) if name.isupper()] + ["choose_iteration", "iteration_costs",
                                                                   "python_step_seconds", "choose_loop",
                                                                   "build_here", "specialised_repays", "load_seconds"]


def iteration_costs(contraction: float, *, separable: bool, s: int, d: int, f_ops: float,
                    lower: bool = False) -> tuple:
    """(fixed point, simplified Newton): the arithmetic operations of one step's stage
    equations by each (module docstring), ``f_ops`` those of one f-evaluation, ``contraction``
    κ = h·‖A_q‖∞·ρ(f′(y₀)); fixed point is ``inf`` where its rate (κ, or κ² on the q stages of a
    separable problem) would not converge within ``STAGE_SWEEPS`` sweeps.  Per sweep both evaluate
    f at the s stages and form the s·d stage sums (2s²d); Newton adds a Jacobian (d² entries of
    about f's size: d·f_ops), its matrix (2(sd)²) and LU (2(sd)³/3; s blocks of d: 2sd³/3), and a
    solve per sweep (2(sd)²; by blocks 3sd² + s²d).

    >>> fixed, newton = iteration_costs(0.2, separable=True, s=3, d=4, f_ops=28)   # Gauss 3, Kepler, h = 1/25
    >>> round(fixed), round(newton)
    (1212, 2884)
    """
    rate = contraction * contraction if separable else contraction
    sums = 2.0 * s * s * d
    sweep = s * f_ops + sums + (s * d if separable else 0.0)     # + the velocities of the q-stage iteration
    sweeps = 1.0 + START_GAP / math.log(1.0 / rate) if 0.0 < rate < 1.0 else (1.0 if rate == 0.0 else math.inf)
    fixed = sweep * sweeps if sweeps <= STAGE_SWEEPS else math.inf
    n = s * d
    if lower:
        factor, solve = 2.0 * s * d ** 3 / 3.0, 3.0 * s * d * d + s * s * d
    else:
        factor, solve = 2.0 * n ** 3 / 3.0, 2.0 * n * n
    newton = d * f_ops + 2.0 * n * n + factor + NEWTON_SWEEPS * (s * f_ops + sums + solve)
    return fixed, newton


def choose_iteration(solver: str, *, explicit: bool, separable: bool, contraction: float, s: int = 1,
                     d: int = 1, f_ops: float = 1.0, lower: bool = False) -> int:
    """The stage iteration mode for ``solver`` "auto", "newton" or "fixedpoint": for "auto" the
    cheaper by :func:`iteration_costs` (its arguments; ties go to fixed point, which needs no
    Jacobian)."""
    if solver not in ("auto", "newton", "fixedpoint"):
        raise ValueError(f"solver must be 'auto', 'newton' or 'fixedpoint', not {solver!r}")
    if explicit or solver == "newton":
        return NEWTON
    if solver == "auto":
        fixed, newton = iteration_costs(contraction, separable=separable, s=s, d=d, f_ops=f_ops, lower=lower)
        if not fixed <= newton:
            return NEWTON
    return SPLIT if separable else FIXED


def python_step_seconds(s: int, r: int, d: int, explicit: bool, projected: int = 0) -> float:
    """The predicted seconds of one step of the pure (Python) float64 loop: s·r stages (a GLM's r
    input values multiply its work), each ``PYTHON_STAGE_SECONDS`` + d·``PYTHON_COMPONENT_SECONDS``,
    ``PYTHON_IMPLICIT_FACTOR`` times that for an implicit method, and ``PYTHON_PROJECTION_FACTOR``
    such stages for each of the ``projected`` invariants (measured: module constants).

    >>> round(python_step_seconds(2, 1, 2, explicit=False) * 1e6)       # Gauss 2, d = 2: measured 77-122 µs
    110
    >>> round(python_step_seconds(1, 1, 2, explicit=True, projected=1) * 1e6)   # Euler + projection: 36 µs
    33
    """
    stage = PYTHON_STAGE_SECONDS + d * PYTHON_COMPONENT_SECONDS
    return (s * r * stage * (1.0 if explicit else PYTHON_IMPLICIT_FACTOR)
            + projected * PYTHON_PROJECTION_FACTOR * stage)


def specialised_repays(python_seconds: float) -> bool:
    """Whether a run predicted at ``python_seconds`` in the pure loop is long enough to repay the
    compile of the loop specialised to it (``COMPILE_COLD_SECONDS``, in the background) against
    the loop shared by every problem: its saving, ``LINKED_SAVED_FRACTION`` of the Python time,
    larger than the compile — about an hour in Python (Gauss 2 on the pendulum: 4·10⁷ steps).

    >>> specialised_repays(600.0), specialised_repays(5000.0)
    (False, True)
    """
    return python_seconds * LINKED_SAVED_FRACTION > COMPILE_COLD_SECONDS


def load_seconds() -> float:
    """What loading a compiled loop from numba's disk cache costs this process:
    ``COMPILE_CACHED_SECONDS``, plus ``NUMBA_START_SECONDS`` while numba is not imported yet."""
    import sys
    return COMPILE_CACHED_SECONDS + (0.0 if "numba" in sys.modules else NUMBA_START_SECONDS)


def choose_loop(steps: int, python_step: float, compile_state, load: float = COMPILE_CACHED_SECONDS) -> tuple:
    """(compiled?, why): the compiled loop when the predicted Python time, ``steps`` ×
    ``python_step`` seconds, exceeds what the compiled loop must pay first — nothing when it is
    "loaded" in this process, ``load`` (:func:`load_seconds`) when numba's disk cache has it
    ("cached"), ``COMPILE_COLD_SECONDS`` for a compile ("cold"); its steps, 100-1000× cheaper,
    are neglected.  Else the Python loop, which starts at once.  ``compile_state`` is one of
    those words (:func:`~.kernels.compile_state`), or a function returning it, asked only when
    the answer matters (looking at the disk cache generates the loop's text).

    >>> choose_loop(629, 160e-6, "cold")
    (False, 'the Python loop: 629 steps predicted at 0.1 s in Python, less than the compile (about 8 s)')
    >>> choose_loop(10**6, 160e-6, lambda: "cold")[0], choose_loop(629, 160e-6, "loaded")[0]
    (True, True)
    >>> print(choose_loop(100, 160e-6, lambda: 1 / 0)[1])       # not asked: less than even a cache load
    the Python loop: 100 steps predicted at 0.016 s in Python, less than loading the cached compiled loop (about 0.5 s)
    """
    python = steps * python_step
    if callable(compile_state):
        compile_state = ("cached" if python <= load else "cold" if python > COMPILE_COLD_SECONDS
                         else compile_state())
    cost = {"loaded": 0.0, "cached": load, "cold": COMPILE_COLD_SECONDS}[compile_state]
    what = {"loaded": "the loop already compiled in this process", "cached": "loading the cached compiled loop",
            "cold": "the compile"}[compile_state]
    if python > cost:
        return True, (f"the compiled loop: {steps} steps predicted at {python:.2g} s in Python, more than "
                      f"{what}" + (f" (about {cost:.2g} s)" if cost else ""))
    return False, (f"the Python loop: {steps} steps predicted at {python:.2g} s in Python, less than {what} "
                   f"(about {cost:.2g} s)")


def build_here(steps: int, s: int, r: int, explicit: bool) -> tuple:
    """(here?, why): where a quick run (``tableau-lab run``, experiments/job.py) does its exact
    stage, decided before anything is built, from the method's s, r and explicitness alone (read
    from its file with json, no sympy) — the problem's dimension d is not known yet, so d = 1, the
    smallest, makes ``steps`` × :func:`python_step_seconds` a lower bound of the Python loop's
    time.  In this process when that bound is at most ``COMPILE_COLD_SECONDS``: the Python loop
    may be chosen (:func:`choose_loop`), and then no second process is worth starting (numba is
    never imported; a short run that goes compiled from the disk cache pays sympy and numba in one
    process, briefly).  Else in a child process, as a compiled run's memory wants.

    >>> build_here(1000, 2, 1, explicit=False)[0], build_here(10**6, 2, 1, explicit=False)[0]
    (True, False)
    >>> print(build_here(10**6, 2, 1, explicit=False)[1])
    a child process builds it: 1000000 steps predicted at 80 s or more in Python, more than the compile (about 8 s)
    """
    low = steps * python_step_seconds(s, r, 1, explicit)
    if low <= COMPILE_COLD_SECONDS:
        return True, (f"built in this process: {steps} steps predicted at {low:.2g} s or more in Python, the "
                      f"Python loop may run (the compile costs about {COMPILE_COLD_SECONDS:.2g} s)")
    return False, (f"a child process builds it: {steps} steps predicted at {low:.2g} s or more in Python, more than "
                   f"the compile (about {COMPILE_COLD_SECONDS:.2g} s)")
