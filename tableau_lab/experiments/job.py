"""A run as data, and its two stages in two processes.

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

from ..numeric.integrate import integrate
from ..process import die_with_parent, scratch_folder

__all__ = ["RunJob", "BuildError", "run_job", "separate_stages"]


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
                            project=self.project, invariants=self.invariants, monitor=self.monitor, progress=tick)
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
        out.update(max_invariant_error=run.max_invariant_error(), nfev=run.nfev,
                   newton_iterations=run.newton_iterations, projection_iterations=run.projection_iterations,
                   seconds=round(run.seconds, 4))
        if run.parasitic_components:
            out["max_parasitic_component"] = {k: max(v) for k, v in run.parasitic_components.items()}
        out["degraded"] = run.degraded() or None        # why the run failed in substance (Run.degraded)
        return out


def separate_stages(precision: str) -> bool:
    """Whether :func:`run_job` builds the run in a child: a compiled run (float64 unless
    TABLEAU_LAB_KERNEL=python, or dd) with numba installed, from a process that has not
    imported sympy (otherwise the saving is gone already)."""
    if "sympy" in sys.modules or precision not in ("float64", "dd"):
        return False
    if precision == "float64" and os.environ.get("TABLEAU_LAB_KERNEL", "auto") == "python":
        return False
    from ..numeric.kernels import available
    return available()


def run_job(build, *args, precision: str = "float64"):
    """``build(*args, frozen=...)`` → a RunJob (the exact stage), then its ``execute()`` here:
    the build in a child Python process, frozen, when :func:`separate_stages` says so.  Errors
    of the build (bad files, parameters) come back as the exceptions it raised."""
    if not separate_stages(precision):
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
