r"""Many independent runs through one interface: in this process, a local process pool, or a Dask
distributed cluster — the same code runs each item in each case, so the results are identical.

    with executor(scheduler=None, workers=None) as ex:
        results = ex.map(fn, items)          # fn(item) for each item, in input order

``scheduler``:

* ``None`` — a process pool on this machine with ``workers`` processes (default: every core);
  ``workers=1`` runs in this process instead.  The pool is started with "forkserver" (no fork
  of a process that has threads) and kept for the next sweep of the same size, so the workers'
  caches (compiled problems, references) stay warm; it ends with the interpreter.
* ``"serial"`` — in this process, one item after another (debugging, tiny sweeps).
* ``"tcp://HOST:PORT"`` — the Dask scheduler at that address (``workers`` is ignored: the
  cluster's workers decide).  The workers need tableau-lab installed, at the same version.
* an open :class:`Executor` — used as it is and left open (one pool for several sweeps).

``fn`` must pickle: a module-level function, or a ``functools.partial`` of one with picklable
arguments.  ``on_result(i, result)`` is called here, in this process, as each item finishes (in
the order they finish), e.g. to write the results that are complete while the others run.  An
exception inside a task comes back as the same exception type, its message prefixed with the
item that raised it ("task 3 of 8 (n=400): ..."); the remaining tasks are cancelled.  A
scheduler that cannot be reached within ``timeout`` seconds raises :class:`SchedulerError`
naming the address.  A progress bar (tqdm, on stderr) is shown when stderr is a terminal, or as
``progress`` says.

No worker outlives its command.  The pool's workers ignore Ctrl-C (SIGINT goes to the whole
process group): the command handles it, and a ``KeyboardInterrupt`` (or ``SystemExit``) during
``map`` kills the workers at once instead of waiting for their tasks.  A command that is killed
(SIGKILL, SIGTERM) cannot end them, so each worker watches the process that started the pool:
on Linux it reads ``/proc/PID/stat`` twice a second (gone, a zombie, or its start time changed:
the worker exits at once) and asks the kernel for SIGKILL when its parent, the forkserver, dies
(``prctl(PR_SET_PDEATHSIG)``); elsewhere it checks the process id.  The forkserver and the
resource tracker end by themselves when the last worker is gone.  A normal exit shuts the
pools down and waits for the workers.

>>> with executor("serial") as ex:
...     ex.map(abs, [-1, 2, -3])
[1, 2, 3]
>>> with executor("serial") as ex:
...     ex.map(abs, [-1, "x"], describe=lambda item: f"item={item}")
Traceback (most recent call last):
TypeError: task 2 of 2 (item=x): bad operand type for abs(): 'str'
"""
from __future__ import annotations

import atexit
import contextlib
import functools
import multiprocessing
import os
import signal
import sys
import threading
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from concurrent.futures.process import BrokenProcessPool

from ..process import alive, die_with_parent, start_time

__all__ = ["executor", "Executor", "SchedulerError", "TaskError"]


class SchedulerError(ConnectionError):
    """The Dask scheduler cannot be reached; the message names the address."""


class TaskError(RuntimeError):
    """A task's exception whose type cannot be rebuilt with a new message (the original is its
    ``__cause__``)."""


class Executor:
    """``map(fn, items, describe=None, desc=None)``: fn(item) for every item, results in input
    order.  ``workers``: how many items run at once (for sizing batches)."""

    workers = 1

    def __init__(self, progress=None):
        self.progress = progress

    def map(self, fn, items, describe=None, desc=None, on_result=None) -> list:
        """``describe(item)`` names an item in error messages (default: its repr); ``desc`` labels
        the progress bar; ``on_result(i, result)`` is called as item i finishes."""
        items = list(items)
        results = [None] * len(items)
        show = sys.stderr.isatty() if self.progress is None else bool(self.progress)
        bar = None
        if show and items:
            from .progress import bar as progress_bar
            bar = progress_bar(len(items), desc, "run")
        outcomes = self._run(fn, items)
        try:
            for i, get in outcomes:
                try:
                    results[i] = get()
                except Exception as exc:    # the task's own exception, named
                    what = describe(items[i]) if describe else _short(repr(items[i]))
                    raise _named(exc, f"task {i + 1} of {len(items)} ({what})") from exc
                if on_result is not None:
                    on_result(i, results[i])
                if bar is not None:
                    bar.update(1)
        except BaseException as exc:
            if not isinstance(exc, Exception):  # Ctrl-C, exit: the running tasks are abandoned
                self._abort()
            raise
        finally:
            outcomes.close()                # cancels what has not run yet
            if bar is not None:
                bar.close()
        return results

    def _run(self, fn, items):
        """Yield (index, get) as the items finish, ``get()`` returning the result or raising the
        task's exception; on close, cancel what remains."""
        for i, item in enumerate(items):
            yield i, functools.partial(fn, item)

    def _abort(self):
        """End the running tasks at once (the pool's workers are killed)."""

    def close(self):
        pass


class _Pool(Executor):
    def __init__(self, workers, progress=None):
        super().__init__(progress)
        self.workers = workers
        self.pool = _shared_pool(workers)

    def _run(self, fn, items):
        try:
            futures = {self.pool.submit(fn, item): i for i, item in enumerate(items)}
        except BrokenProcessPool:               # a worker died since the last sweep: a new pool
            _drop_pool(self.workers, self.pool)
            self.pool = _shared_pool(self.workers)
            futures = {self.pool.submit(fn, item): i for i, item in enumerate(items)}
        try:
            for f in as_completed(futures):
                if isinstance(f.exception(), BrokenProcessPool):
                    _drop_pool(self.workers, self.pool)
                yield futures[f], f.result
        finally:
            for f in futures:
                f.cancel()

    def _abort(self):
        _drop_pool(self.workers, self.pool, kill=True)


class _Dask(Executor):
    def __init__(self, address, timeout, progress=None):
        super().__init__(progress)
        from distributed import Client
        from distributed.comm import parse_address, parse_host_port
        try:
            parse_host_port(parse_address(address, strict=True)[1])
        except ValueError as exc:
            raise ValueError(f"a Dask scheduler address looks like tcp://HOST:PORT, not {address!r} ({exc})") from None
        try:
            self.client = Client(address, timeout=timeout, set_as_default=False)
        except (OSError, TimeoutError, ValueError, TypeError) as exc:    # TypeError: tls:// without a security context
            raise SchedulerError(f"cannot reach the Dask scheduler at {address} within {timeout:g} s "
                                 f"({type(exc).__name__}: {exc})") from exc
        self.workers = max(1, sum(self.client.nthreads().values()))

    def _run(self, fn, items):
        from distributed import as_completed as dask_completed
        futures = self.client.map(fn, items, pure=False)
        index = {f.key: i for i, f in enumerate(futures)}
        try:
            for f in dask_completed(futures, loop=self.client.loop):
                yield index[f.key], f.result
        finally:
            self.client.cancel([f for f in futures if not f.done()])

    def close(self):
        self.client.close()


@contextlib.contextmanager
def executor(scheduler=None, workers: int | None = None, *, timeout: float = 5.0, progress=None):
    """The executor for ``scheduler`` (see the module's docstring), closed on exit."""
    if isinstance(scheduler, Executor):
        yield scheduler
        return
    if workers is not None and int(workers) < 1:
        raise ValueError(f"workers must be at least 1, not {workers}")
    if scheduler == "serial" or (scheduler is None and workers == 1):
        ex = Executor(progress)
    elif scheduler is None:
        ex = _Pool(int(workers or os.cpu_count() or 1), progress)
    elif isinstance(scheduler, str) and scheduler:
        ex = _Dask(scheduler, timeout, progress)
    else:
        raise ValueError(f"scheduler must be None, 'serial' or a Dask address (tcp://HOST:PORT), not {scheduler!r}")
    try:
        yield ex
    finally:
        ex.close()


_POOLS: dict = {}          # workers -> ProcessPoolExecutor, kept for the next sweep
_POOLS_LOCK = threading.Lock()


def _shared_pool(workers: int) -> ProcessPoolExecutor:
    with _POOLS_LOCK:
        if workers not in _POOLS:
            method = "forkserver" if "forkserver" in multiprocessing.get_all_start_methods() else "spawn"
            me = os.getpid()
            _POOLS[workers] = ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context(method),
                                                  initializer=_worker_start, initargs=(me, start_time(me)))
        return _POOLS[workers]


def _drop_pool(workers, pool, kill=False):
    """A pool whose worker died cannot take more work: the next sweep starts a new one.
    ``kill``: its workers are killed first (their tasks abandoned)."""
    with _POOLS_LOCK:
        if _POOLS.get(workers) is pool:
            del _POOLS[workers]
    if kill:
        for p in list((getattr(pool, "_processes", None) or {}).values()):
            with contextlib.suppress(Exception):
                p.kill()
    pool.shutdown(wait=False, cancel_futures=True)


def _worker_start(parent: int, started) -> None:
    """A pool worker's initializer: Ctrl-C is the command's to handle; the worker ends when the
    command is gone (module docstring)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    die_with_parent()
    if not alive(parent, started):
        os._exit(1)
    threading.Thread(target=_watch_parent, args=(parent, started), daemon=True,
                     name="tableau-lab: watch the command").start()


def _watch_parent(parent: int, started, every: float = 0.5) -> None:
    while True:
        time.sleep(every)
        if not alive(parent, started):
            os._exit(1)


@atexit.register
def _shutdown_pools():
    with _POOLS_LOCK:
        pools = list(_POOLS.values())
        _POOLS.clear()
    for pool in pools:
        pool.shutdown(wait=True, cancel_futures=True)


def _named(exc: BaseException, where: str) -> BaseException:
    """``exc``'s type with the message "where: message" (TaskError where the type needs other
    arguments)."""
    msg = f"{where}: {exc}"
    try:
        new = type(exc)(msg)
        if str(new) == msg:
            return new
    except Exception:           # constructors with other signatures
        pass
    return TaskError(f"{where}: {type(exc).__name__}: {exc}")


def _short(text: str, most: int = 60) -> str:
    return text if len(text) <= most else text[:most - 1] + "…"
