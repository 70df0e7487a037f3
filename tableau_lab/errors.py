"""The project's error kinds, and what the command line does with each (defined once).

* :class:`InputError` (a ``ValueError``): bad input — a file, an entry, an option. Every loader's
  error (``TableauError``, ``EntryError``, ``SceneError``, ``ProblemError``, ``MethodError`` …)
  derives from it. The CLI prints its message (which names the file, entry or option) and exits 2;
  nothing is written.
* :class:`BudgetError` (an ``InputError``): a size, degree or time budget was hit. The message
  names the budget, its value, what was being computed and the option that raises it.
* Anything else that escapes a command is a bug: one line asking for a report, exit 3, the
  traceback only with ``--debug``.

A run that fails honestly (``IntegrationError``: the step and time named) exits 1, as a failed
claim does. A run that goes to its end but fails in substance — an invariant error or a parasitic
component of relative size ``numeric.limits.DEGRADED`` (1e-2) or more — is "degraded": exit 4.
This module imports nothing of the package: every layer may use it.

>>> issubclass(BudgetError, ValueError)
True
"""
from __future__ import annotations

__all__ = ["InputError", "BudgetError", "Terminated", "EXIT_TERMINATED", "EXIT_OK", "EXIT_CLAIM", "EXIT_INPUT",
           "EXIT_BUG", "EXIT_INTERRUPTED", "EXIT_DEGRADED"]

EXIT_OK, EXIT_CLAIM, EXIT_INPUT, EXIT_BUG, EXIT_INTERRUPTED, EXIT_TERMINATED = 0, 1, 2, 3, 130, 143
EXIT_DEGRADED = 4           # every run went to its end, one (or more) degraded


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised where Ctrl-C would be: the same clean stop (finished runs saved, no half
    file), exit 143."""


class InputError(ValueError):
    """Bad input: the message names the file, entry or option and the reason (exit 2)."""


class BudgetError(InputError):
    """A budget (size, degree, time) was hit before or during an analysis (exit 2).

    ``budget``: its name (e.g. ``"time"``, ``"field degree"``); ``limit``: its value; ``what``:
    what was being computed; ``option``: how to raise it (e.g. ``"--timeout S"``)."""

    def __init__(self, budget: str, limit, what: str, option: str | None = None):
        self.budget, self.limit, self.what, self.option = budget, limit, what, option
        raise_it = f"; raise it with {option}" if option else ""
        super().__init__(f"{what}: {budget} budget of {limit} exceeded{raise_it}")
