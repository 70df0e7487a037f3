"""Progress bars for long integrations (tqdm, on stderr, shown only when stderr is a terminal):
the scene runs and the quick ``tableau-lab run`` of many steps.  Sweeps show theirs through the
executor (:mod:`executor`)."""
from __future__ import annotations

import sys

__all__ = ["StepBar", "QUICK_RUN_BAR_STEPS", "bar"]

QUICK_RUN_BAR_STEPS = 10 ** 6      # a quick run of at least this many steps shows a bar


def bar(total: int, desc: str | None, unit: str):
    """A tqdm bar on the process's own stderr: the CLI wraps ``sys.stderr`` to escape terminal
    control characters of untrusted text (:func:`inputs.printable`), which would garble the
    bar's own; the description (it may name a file's method) is escaped here instead."""
    from tqdm import tqdm

    from ..inputs import printable
    return tqdm(total=total, desc=None if desc is None else printable(desc), unit=unit, leave=False,
                file=sys.__stderr__ or sys.stderr)


class StepBar:
    """``integrate``'s ``progress(n)`` callback drawing a bar of ``total`` steps; a no-op when
    ``show`` is False (default: when stderr is a terminal).  A context manager: the bar is
    removed when the run ends, however it ends.

    >>> with StepBar(10, "test", show=False) as tick:
    ...     tick(5)
    """

    def __init__(self, total: int, desc: str, show: bool | None = None):
        self.bar, self.last = None, 0
        if sys.stderr.isatty() if show is None else show:
            self.bar = bar(total, desc, "step")

    def __call__(self, n: int) -> None:
        if self.bar is not None:
            self.bar.update(n - self.last)
            self.last = n

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        if self.bar is not None:
            self.bar.close()
        return False
