"""Time budgets for the exact analyses, and what was being computed when one ran out.

Exact work (Gröbner bases, order conditions of high order, number fields of high degree) can
run for hours on legal but hopeless input. Every exact command runs within a time budget
(``--timeout S``, default :data:`DEFAULT_SECONDS`; 0 for none); when it runs out the work stops
with a :class:`~tableau_lab.errors.BudgetError` that names the budget, what was being computed
(the innermost :func:`computing` label) and the option that raises it.

The budget is a real-time alarm (``SIGALRM``), so it works only in the main thread of a POSIX
process; elsewhere :func:`time_limit` runs the work unbounded (the size budgets still hold).

>>> with time_limit(5):
...     with computing("a quick sum"):
...         sum(range(10))
45

Work that swallows the budget's error and raises its own is still stopped by the budget:

>>> def wrapped():
...     try:
...         while True:
...             pass
...     except ValueError:
...         raise RuntimeError("not in any domain")
>>> with time_limit(0.05):
...     with computing("a wrapped loop"):
...         wrapped()
Traceback (most recent call last):
...
tableau_lab.errors.BudgetError: a wrapped loop: time budget of 0.05 s exceeded; raise it with --timeout S
"""
from __future__ import annotations

import signal
import threading
from contextlib import contextmanager

from .errors import BudgetError

__all__ = ["DEFAULT_SECONDS", "FIELD_DEGREE", "SERIES_ORDER", "MODIFIED_ORDER", "OPTION", "computing", "time_limit",
           "current", "CERTIFIED_SECONDS", "CERTIFIED_TREES", "SSP_R_MAX",
           "REAL_X_MAX"]

DEFAULT_SECONDS = 300.0       # the default budget of one exact command (the slowest shipped analysis: ~15 s)
FIELD_DEGREE = 64             # the default degree budget of a method's number field (exact/field.py)
SERIES_ORDER = 12             # the highest order of a B-series (order 12: 4766 trees, 2^11 edge subsets each)
MODIFIED_ORDER = 10           # the highest --order of `tableau-lab modified` (order 10: 719 trees, about a minute)
OPTION = "--timeout S"        # how a user raises it
#: the certified (ball) analysis of a decimal tableau: its order conditions stop after this many seconds or trees
#: and say "undecided" (order 10 of a 7-stage tableau: 1842 trees, well under a second at 20 digits)
AUDIT_SECONDS = 60.0        # the default budget of one method in `tableau-lab audit` (--seconds)
CERTIFIED_SECONDS = 60.0
CERTIFIED_TREES = 100_000
#: the certified SSP coefficient looks for an upper bound r = 1, 2, 4, … up to this (beyond: "R ≥ …", undecided)
SSP_R_MAX = 1024
#: the certified real stability interval walks from 0 to −REAL_X_MAX at most (beyond: "β ≥ …", undecided)
REAL_X_MAX = 1024

_STACK: list[str] = []


@contextmanager
def computing(what: str):
    """Label the enclosed work for the message of a budget that runs out (:func:`current`)."""
    _STACK.append(what)
    try:
        yield
    finally:
        _STACK.pop()


def current(default: str = "the analysis") -> str:
    """What is being computed now: the outermost and the innermost :func:`computing` labels.

    >>> with computing("solve of m.json"), computing("Gröbner basis of 3 equations in 2 unknowns"):
    ...     current()
    'solve of m.json: Gröbner basis of 3 equations in 2 unknowns'
    """
    if not _STACK:
        return default
    return _STACK[0] if len(_STACK) == 1 else f"{_STACK[0]}: {_STACK[-1]}"


@contextmanager
def time_limit(seconds: float | None, option: str = OPTION):
    """Raise BudgetError in the enclosed work after ``seconds`` (None or 0: no limit).  Inside
    an enclosing budget (its alarm already set) the enclosing one governs."""
    usable = (seconds and seconds > 0 and hasattr(signal, "setitimer")
              and threading.current_thread() is threading.main_thread()
              and signal.getitimer(signal.ITIMER_REAL)[0] == 0)
    if not usable or seconds is None:
        yield
        return

    fired: list = []

    def expire(signum, frame):
        signal.setitimer(signal.ITIMER_REAL, 0)
        fired.append(BudgetError("time", f"{seconds:g} s", current(), option))
        raise fired[0]

    old = signal.signal(signal.SIGALRM, expire)
    signal.setitimer(signal.ITIMER_REAL, float(seconds))
    try:
        yield
    except Exception as exc:
        # library code that catches ValueError (the BudgetError) and raises its own error in its
        # place (sympy's domain conversion: "CoercionFailed: ... is not in any domain") must not
        # turn the budget into an internal error: once the budget fired, it is the cause
        if fired and exc is not fired[0]:
            raise fired[0] from exc
        raise
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)
