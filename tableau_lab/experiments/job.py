"""A run as data, and its two stages in one process or two.

Building a run is exact work — read and check the method, build the problem, round the
coefficients, generate the problem's code: sympy (and python-flint under it), about 60 MB
resident.  A long compiled run needs numba's runtime and LLVM, about 130 MB.  One process
holding both peaks near 210 MB however short the run; so when the caller has not imported
sympy itself, :func:`run_job` does the exact stage in a child Python process (it exits when
done) that returns a :class:`RunJob` — the numeric method and the problem's generated code,
frozen (``numeric/frozen.py``), the step at the working precision, the options — and the
caller, which never imports sympy, runs the loop.  The two stages never coexist, so the run's
peak is the loop's (``tableau-lab bench``, memory row).  Results are the same bit for bit: the
frozen code is the generated code (tests/test_job.py).

A short run is built here instead (:func:`separate_stages`, ``limits.build_here``): when the
Python loop may be the one that runs (``integrate(kernel="cost")``: its predicted time against
the compile), a second process would cost more than the run (about 1 s to start and import),
and numba is never imported.  Where to build is decided before building, from the method's
file read with json alone (:func:`method_shape`).

Nothing in this module imports sympy.
"""
from __future__ import annotations

import os
import pickle
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import mpmath

from ..inputs import read_json
from ..numeric.integrate import integrate
from ..numeric.limits import QUICK_RUN_RECORDS, build_here
from ..process import die_with_parent, scratch_folder

__all__ = ["RunJob", "BuildError", "run_job", "separate_stages", "method_shape"]


class BuildError(RuntimeError):
    """The build process ended without a result (killed, out of memory, crashed)."""


@dataclass
class RunJob:
    """Everything the numeric stage of a quick run needs (picklable, no symbols)."""
    nm: object                 # NumericMethod (frozen: exact=None)
    prob: object               # FrozenProblem or CompiledProblem
    h: object                  # at the working precision (float, or mpf)
    steps: int
    start: str
    project: tuple
    invariants: tuple
    monitor: float | None
    precision: str
    method: str                # names, for the report
    problem: str
    q_count: int | None        # Hamiltonian problems: how many q components

    def execute(self) -> dict:
        """Run it; the result as a JSON-ready dict (final state through the finishing method)."""
        from .progress import QUICK_RUN_BAR_STEPS, StepBar
        with StepBar(self.steps, f"{self.method} on {self.problem}",
                     show=None if self.steps >= QUICK_RUN_BAR_STEPS else False) as tick:
            run = integrate(self.nm, self.prob, self.prob.y0, self.h, self.steps, start=self.start,
                            project=self.project, invariants=self.invariants, monitor=self.monitor, progress=tick,
                            kernel="cost", record_every=max(1, self.steps // QUICK_RUN_RECORDS))
        if self.precision == "float64":
            final = [float(x) for x in run.final]
        else:                                     # all digits of a multiprecision run, as strings
            final = [mpmath.nstr(x, self.nm.arith.dps, strip_zeros=False) for x in run.final]
        out = {"method": self.method, "problem": self.problem, "h": float(self.h), "steps": self.steps,
               "precision": self.precision, "start": run.start, "projection": list(self.project),
               "records": len(run.times)}
        if self.q_count is not None:
            out["final"] = {"q": final[:self.q_count], "p": final[self.q_count:]}
        else:
            out["final"] = {"y": final}
        out.update(max_invariant_error=run.max_invariant_error(), nfev=run.nfev,  # seconds: without the compile
                   newton_iterations=run.newton_iterations, projection_iterations=run.projection_iterations,
                   seconds=round(run.seconds, 4), loop=run.loop, loop_why=run.loop_why,
                   compile_seconds=round(run.compile_seconds, 3))
        if run.parasitic_components:
            out["max_parasitic_component"] = {k: max(v) for k, v in run.parasitic_components.items()}
        out["degraded"] = run.degraded() or None        # why the run failed in substance (Run.degraded)
        return out


def method_shape(method) -> tuple | None:
    """(s, r, explicit) of the method file ``method``, read with json alone (no sympy), or None
    when it is not a file of a known kind with square matrices (a shipped method's name, a
    family, a bad file: the build says what is wrong).  An entry counts as zero when it is 0 or "0"; any other entry on
    or above the diagonal makes the method implicit.

    >>> method_shape("methods/gauss2.json"), method_shape("methods/glm43.json"), method_shape("rk4")
    ((2, 1, False), (4, 3, False), None)
    >>> method_shape("methods/rk4.json")
    (4, 1, True)
    """
    try:
        if not os.path.isfile(method):
            return None
        data = read_json(method, ValueError, "tableau")
        mats = [data["A"]] + ([data["Ahat"]] if data["kind"] == "prk" else [])
        r = len(data["V"]) if data["kind"] == "glm" else 1 if data["kind"] in ("rk", "prk") else 0
        s = len(mats[0])
        if not all(isinstance(A, list) and len(A) == s and all(isinstance(row, list) and len(row) == s for row in A)
                   for A in mats):
            return None
        explicit = all(A[i][j] in (0, "0") for A in mats for i in range(s) for j in range(i, len(A[i])))
    except (ValueError, KeyError, TypeError, IndexError, OSError):
        return None
    return (s, r, explicit) if s and r else None


def separate_stages(precision: str, method=None, steps: int | None = None) -> bool:
    """Whether :func:`run_job` builds the run in a child: a compiled run (float64 unless
    TABLEAU_LAB_KERNEL=python, or dd) with numba installed, from a process that has not
    imported sympy (otherwise the saving is gone already) — and, in float64 given the method's
    file and the steps, not a run the Python loop may serve (``limits.build_here``, on
    :func:`method_shape`; a method whose shape is not read that way is built in a child)."""
    if "sympy" in sys.modules or precision not in ("float64", "dd"):
        return False
    if precision == "float64" and os.environ.get("TABLEAU_LAB_KERNEL", "auto") == "python":
        return False
    shape = method_shape(method) if precision == "float64" and method is not None and steps else None
    if shape is not None and build_here(int(steps), *shape)[0]:
        return False
    from ..numeric.kernels import available
    return available()


def run_job(build, *args, precision: str = "float64", method=None, steps: int | None = None):
    """``build(*args, frozen=...)`` → a RunJob (the exact stage), then its ``execute()`` here:
    the build in a child Python process, frozen, when :func:`separate_stages` says so (``method``,
    ``steps``: the run's method file and steps, for its rule).  Errors of the build (bad files,
    parameters) come back as the exceptions it raised."""
    if not separate_stages(precision, method, steps):
        return build(*args, frozen=False).execute()
    with scratch_folder(JOB_PREFIX) as tmp:
        task, result = Path(tmp) / "task.pickle", Path(tmp) / "job.pickle"
        task.write_bytes(pickle.dumps((build, args)))
        done = subprocess.run([sys.executable, "-m", "tableau_lab.experiments.job", str(task), str(result)],
                              stdin=subprocess.DEVNULL)
        if not result.exists():
            raise BuildError(f"the build process of this run ended with exit code {done.returncode} "
                               "and no result (see its messages above)")
        ok, value = pickle.loads(result.read_bytes())
    if not ok:
        raise value
    return value.execute()


JOB_PREFIX = "tableau_lab_job_"         # its folder in the temporary directory: + the pid + "_"


def _child(task: str, result: str) -> None:
    """``python -m tableau_lab.experiments.job TASK RESULT``: build, write (True, job) or
    (False, exception) to RESULT.  It dies with the command that started it."""
    die_with_parent()
    build, args = pickle.loads(Path(task).read_bytes())
    try:
        out = (True, build(*args, frozen=True))
    except Exception as exc:                 # handed to the parent, raised there
        out = (False, exc)
    try:
        data = pickle.dumps(out)
        pickle.loads(data)
    except Exception:                        # an exception that does not round-trip: its message does
        exc = out[1]
        data = pickle.dumps((False, (ValueError if isinstance(exc, ValueError) else RuntimeError)(str(exc))))
    Path(result).write_bytes(data)


if __name__ == "__main__":
    _child(*sys.argv[1:3])
