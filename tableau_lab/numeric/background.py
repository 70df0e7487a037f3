"""A compiled loop made in a background process while the pure loop runs (issue 32).

A run whose loop is not compiled yet need not wait for numba: it starts at once in the pure
(Python) loop, while a child process (``python -m tableau_lab.numeric.background``) imports the
generated modules and makes numba compile the loop's ``run`` into its disk cache.  Between two
chunks of steps, :func:`kernels.drive <.kernels.drive>` asks the switch this module hands it
whether the compile is done; it then continues the same run, on the same arrays, in the compiled
loop (loaded from the cache), from the next step.  The two loops execute the same code
(:mod:`stepcore`), so the switched run agrees with the pure one to round-off, step counts and
counters included (tests/test_background.py).

One compile runs at a time (``limits.BACKGROUND_COMPILES``: a machine of two cores gives one to
the run, one to numba); others wait in a queue, started as one finishes.  A compile outlives
the run that asked for it (the next run of the same loop in this process, a scene's or a
notebook's, finds it done) but not the process: it dies with it (``die_with_parent``).

>>> worth(10.0), worth(0.1)                 # predicted seconds of the run in Python
(True, False)
"""
from __future__ import annotations

import os
import pickle
import subprocess
import sys
import time

from ..process import die_with_parent
from . import kernels, limits as L

__all__ = ["worth", "possible", "Compile", "start", "start_shared", "announce", "announce_shared", "switch_when_ready",
           "wait_all", "pending"]


def possible() -> bool:
    """numba is installed and background compiles are not turned off (the environment variable
    TABLEAU_LAB_BACKGROUND set to "0": the test suite, which compiles what it needs itself)."""
    return os.environ.get("TABLEAU_LAB_BACKGROUND", "1") != "0" and kernels.available()


def worth(python_seconds: float) -> bool:
    """Whether a run predicted to take ``python_seconds`` in the pure loop should compile its
    loop in the background: longer than ``limits.BACKGROUND_AFTER_SECONDS`` (shorter runs end
    before a compile could help them)."""
    return python_seconds > L.BACKGROUND_AFTER_SECONDS


class Compile:
    """One background compile: the generated modules' (name, path), the argument tuple whose
    types numba compiles ``run`` for, the child process once started, and whether it ended well
    (``ok``: its exit status was 0; None while it runs or waits)."""

    def __init__(self, files: tuple, args: tuple):
        self.files, self.args = files, args
        self.proc: subprocess.Popen | None = None
        self.ok: bool | None = None

    def launch(self) -> None:
        self.proc = subprocess.Popen([sys.executable, "-m", "tableau_lab.numeric.background"],
                                     stdin=subprocess.PIPE, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        try:
            assert self.proc.stdin is not None
            self.proc.stdin.write(pickle.dumps((self.files, self.args)))
            self.proc.stdin.close()
        except OSError:                      # the child died at once: the run stays in Python
            self.ok = False

    def poll(self) -> bool | None:
        """True once compiled (and in the disk cache), False if the compile failed, None while it runs."""
        if self.ok is None and self.proc is not None and self.proc.poll() is not None:
            self.ok = self.proc.returncode == 0
        return self.ok


MAX_TASK_BYTES = 2 ** 20    # the task a child reads: module names and paths, and the arguments of one step (a few kB)
_ALL: dict = {}            # module name -> Compile, this process's, started or queued


def pending() -> list:
    """The compiles started or queued in this process and not ended."""
    return [c for c in _ALL.values() if c.ok is None]


def _advance() -> None:
    """Start queued compiles while fewer than ``limits.BACKGROUND_COMPILES`` run."""
    running = [c for c in _ALL.values() if c.proc is not None and c.poll() is None]
    for c in _ALL.values():
        if len(running) >= L.BACKGROUND_COMPILES:
            break
        if c.proc is None and c.ok is None:
            c.launch()
            running.append(c)


def start(problem, kind: str, shape, args: tuple) -> Compile:
    """The background compile of the loop of ``problem`` for ``kind`` and ``shape``
    (:func:`kernels.loop_files <.kernels.loop_files>`, written now), for arguments of the types
    of ``args`` (a :class:`~.kernels.LoopState`'s ``args(0, 0)``): started, or queued behind the
    one running; the same compile once per process."""
    return _queued(kernels.loop_files(problem, kind, shape), args, lambda: announce(problem, kind))


def start_shared(shape, args: tuple) -> Compile:
    """The background build of the float64 loop shared by every problem for the stage iteration
    and projection of ``shape`` (:func:`kernels.linked_loop <.kernels.linked_loop>`; its files
    written now in :func:`~.kernels.shared_dir`), for arguments of the types of ``args`` (those of
    a pure run, ``c`` made the linked record with no address: :func:`~.kernels.linked_data`):
    started, or queued behind the one running; once per process, whichever problem asks.  Once
    built, it serves every later run of that stage iteration and projection, of any problem, in
    this process and the next ones (the cost rule's linked loop)."""
    data = kernels.linked_data(args[4])                      # LoopState.args: the problem's data fifth
    return _queued(kernels.linked_files(shape), (*args[:4], data, *args[5:]), lambda: announce_shared(shape))


def _queued(files: tuple, args: tuple, told) -> Compile:
    """The compile of the loop module ``files`` (:func:`_child`'s task), once per process: queued
    (``told()`` then announces it) and started when a place is free (:func:`_advance`)."""
    c = _ALL.get(files[2])
    if c is None:
        c = _ALL[files[2]] = Compile(files, args)
        told()
    _advance()
    return c


_TOLD: set = set()         # (problem key, kind) announced in this process


def announce(problem, kind: str) -> None:
    """The one-line notice on stderr, once per problem and arithmetic in this process: its step
    loops compile in the background (one-off: cached on disk), the runs go on in Python meanwhile."""
    key = (problem.key, kind)
    if key in _TOLD:
        return
    _TOLD.add(key)
    where = kernels.cached_in(kernels.cache_dir())
    kernels.notice(f"compiling the step loop{'' if kind == 'f64' else ' (' + kind + ')'} for "
                   f"{getattr(problem, 'name', 'this problem')} in the background ({where}); "
                   "running in Python meanwhile")


def announce_shared(shape) -> None:
    """The notice of :func:`start_shared`, once per shared loop in this process."""
    key = ("shared", shape.mode, shape.projects)
    if key in _TOLD:
        return
    _TOLD.add(key)
    what = kernels.shape_text(kernels.generic_shape(shape))
    kernels.notice(f"building the step loop shared by every problem (float64, {what}) in the background "
                   f"({kernels.cached_in(kernels.shared_dir())}); running in Python meanwhile")


def switch_when_ready(*choices):
    """The ``switch`` of :func:`kernels.drive <.kernels.drive>`: ``choices`` are (Compile, ready)
    pairs, the best loop first; the switch returns ``ready()`` of the best one whose compile has
    ended well and that is better than the one it last returned (None otherwise: a failed compile
    is passed over for good).  A pure run moves to the linked loop once built, then to its
    specialised loop once compiled, if that was asked."""
    best = [len(choices)]                    # the index of the loop running: none of these yet

    def switch():
        _advance()
        for i, (c, ready) in enumerate(choices[:best[0]]):
            if c.poll() is True:
                best[0] = i
                return ready()
        return None
    return switch


def wait_all(timeout: float | None = None) -> bool:
    """Wait for this process's background compiles (tests, benchmarks): True if all ended."""
    t_end = None if timeout is None else time.perf_counter() + timeout
    while pending():
        _advance()
        if t_end is not None and time.perf_counter() > t_end:
            return False
        time.sleep(0.05)
    return True


def _child() -> None:
    """``python -m tableau_lab.numeric.background`` < pickle of (files, args): load the problem
    and loop modules by path and call ``run`` once with no step (numba compiles it and writes
    its disk cache).  It dies with the process that started it."""
    die_with_parent()
    (pname, ppath, name, path), args = pickle.loads(sys.stdin.buffer.read(MAX_TASK_BYTES))
    kernels.load_module(pname, ppath)
    kernels.load_module(name, path).run(*args)


if __name__ == "__main__":
    _child()
