r"""Output files, for every layer: written atomically, cleaned up after crashes, one writer per
output folder at a time.

* **Atomic.** ``atomic_write(target, write)`` calls ``write(temporary_path)``, flushes the file to
  the disk (``fsync``) and moves it onto ``target`` with ``os.replace``: a reader, and a process
  killed at any moment, sees the old file or the whole new one, never a half-written one.
* **Temporary names** are ``.<target name>.tltmp-<pid>-<random><suffix>``: hidden, recognisable
  (:data:`TEMP_PATTERN`) and carrying the writer's process id.  A process killed by SIGKILL cannot
  remove its temporary file, so the first atomic write of a process into a folder removes every
  such file there whose process is gone (:func:`remove_stale_temps`; a process id on this
  machine; files without the mark are never touched, except the unmarked ``mkstemp`` names of
  earlier versions, ``.<name>.XXXXXXXX<suffix>``, once they are an hour old).
* **Errors.** An ``OSError`` while writing (``ENOSPC``: the disk is full, ``EDQUOT``, ``EACCES``,
  ``EROFS`` …) removes the temporary file, leaves the previous ``target`` as it was and is raised
  as :class:`OutputError`, whose message names the file and the reason.
* **Sets of files.** Inside ``with output_set():`` every atomic write is *staged* (written in full
  and synced under its temporary name) and the whole set is moved into place when the block ends
  without an exception.  On an exception (a full disk half-way through, a second Ctrl-C) every
  staged file is removed and the folder keeps its previous set: data, metadata and plots of a
  scene never come from two different runs (except for a SIGKILL inside the microseconds of the
  final renames).
* **Concurrency (the choice: an advisory lock per output folder).** ``output_lock(folder)`` takes
  ``fcntl.flock`` on ``folder/.tableau-lab.lock`` for the write phase only (the computations of
  two runs overlap; their writes do not).  A second process that writes into the same folder
  waits for the first (saying on stderr which process holds the folder), then writes its own
  complete set, so the folder always holds one run's files, never a mixture; after ``timeout``
  seconds (``TABLEAU_LAB_LOCK_TIMEOUT``, default 600) it gives up with an :class:`OutputError`
  naming the folder and the holder.  The holder removes the lock file before it unlocks it, and
  a process that gets the lock of a file that is no longer there tries again, so no lock file
  stays behind (a killed holder's file is removed by the next writer).  Deleting the previous
  run's files tolerates files that are gone already (a writer that does not lock, a user).
  The lock is advisory: it orders
  tableau-lab processes, on one machine or on a network file system whose ``flock`` is
  honoured (NFS on Linux emulates it with ``fcntl`` locks).
* **Ctrl-C.** ``deferred_interrupt()`` holds SIGINT during a write phase: the first Ctrl-C is noted
  on stderr and raised as ``KeyboardInterrupt`` when the phase ends (the results are written
  first); a second Ctrl-C raises at once (and the staged set is abandoned).

``output_phase(folder)`` is the three together: lock, deferred Ctrl-C, one staged set.
"""
from __future__ import annotations

import contextlib
import errno as _errno
import os
import re
import secrets
import shutil
import signal
import sys
import threading
import time
from pathlib import Path

from .process import alive

__all__ = ["atomic_write", "atomic_write_text", "atomic_copy", "OutputError", "output_set", "output_lock",
           "output_phase", "deferred_interrupt", "remove_stale_temps", "is_temp", "TEMP_PATTERN", "LOCK_NAME"]

TEMP_MARK = ".tltmp-"
# .<target name>.tltmp-<pid>-<random><suffix>
TEMP_PATTERN = re.compile(r"^\..+\.tltmp-(?P<pid>\d+)-[0-9a-f]{8}(\.[A-Za-z0-9]+)?$")
# earlier versions: tempfile.mkstemp(prefix=".<name>.", suffix=...), no process id
_LEGACY = re.compile(r"^\.(?P<name>.+?(?P<ext>\.[A-Za-z0-9]+))\.[a-z0-9_]{8}(?:(?P=ext)|\.tmp)$")
_LEGACY_AGE = 3600.0
LOCK_NAME = ".tableau-lab.lock"


class OutputError(OSError):
    """An output file or folder that cannot be written (a full disk, no permission, a folder
    held by another process too long).  The message names the file; the previous file is left
    as it was.  ``errno`` is the underlying error's; the message is the whole text (no
    ``[Errno N]`` prefix)."""

    def __str__(self):
        return self.strerror or super().__str__()


def is_temp(name: str) -> bool:
    """Whether a file name is one of our temporary files (of any process, alive or not)."""
    return bool(TEMP_PATTERN.match(name))


def remove_stale_temps(folder) -> list:
    """Remove the temporary files in ``folder`` left by processes that are gone (killed while
    writing); returns the names removed.  Temporary files of live processes are kept."""
    removed = []
    try:
        names = os.listdir(folder)
    except OSError:
        return removed
    now = time.time()
    for name in names:
        m = TEMP_PATTERN.match(name)
        stale = False
        if m:
            stale = not alive(int(m["pid"]))
        elif name.startswith(".") and _LEGACY.match(name):
            try:
                stale = now - os.stat(os.path.join(folder, name)).st_mtime > _LEGACY_AGE
            except OSError:
                continue
        if stale:
            try:
                os.unlink(os.path.join(folder, name))
                removed.append(name)
            except FileNotFoundError:
                pass
            except OSError:
                pass                        # not ours to remove after all (permissions): left
    return removed


_CLEANED: set = set()          # folders this process has cleaned already
_STATE = threading.local()     # .stage: the staged set of this thread (output_set), or None


def _clean_once(folder: Path):
    key = os.path.abspath(folder)
    if key not in _CLEANED:
        remove_stale_temps(folder)
        _CLEANED.add(key)


def _temp_path(target: Path, suffix: str) -> Path:
    return target.parent / f".{target.name}{TEMP_MARK}{os.getpid()}-{secrets.token_hex(4)}{suffix}"


def _fill(tmp: str, write) -> None:
    """``write(tmp)``, then the file flushed to the disk (a full disk shows here at the latest)."""
    write(tmp)
    fd = os.open(tmp, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def _error(target, exc: OSError, doing="write") -> OutputError:
    reason = exc.strerror or str(exc) or type(exc).__name__
    if exc.errno == _errno.ENOSPC:
        reason += " (the disk is full)"
    err = OutputError(exc.errno or 0, f"{target}: cannot {doing} it: {reason}; the previous "
                                      f"{Path(target).name}, if any, is left as it was")
    return err


def _unlink(path) -> None:
    try:
        os.unlink(path)
    except FileNotFoundError:
        pass
    except OSError:
        pass


def atomic_write(target, write, suffix: str = ".tmp") -> Path:
    """Call ``write(temporary_path)``, then move the result onto ``target`` (its folder is made).
    ``suffix`` is the temporary file's ending, for writers that choose the format by it.  Inside
    :func:`output_set` the file is staged and moved into place when the set ends.  An
    ``OSError`` leaves ``target`` as it was and is raised as :class:`OutputError`."""
    target = Path(target)
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise _error(target, exc, "create the folder of") from exc
    _clean_once(target.parent)
    tmp = _temp_path(target, suffix)
    stage = getattr(_STATE, "stage", None)
    try:
        os.close(os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666))     # the umask applies
        _fill(str(tmp), write)
        if stage is not None:
            stage.append((tmp, target))
            return target
        os.replace(tmp, target)
    except OSError as exc:
        _unlink(tmp)
        if isinstance(exc, OutputError):
            raise
        raise _error(target, exc) from exc
    except BaseException:
        _unlink(tmp)
        raise
    return target


def atomic_write_text(target, text: str) -> Path:
    return atomic_write(target, lambda tmp: Path(tmp).write_text(text, encoding="utf-8"))


def atomic_copy(source, target) -> Path:
    """Copy ``source`` onto ``target`` atomically (see :func:`atomic_write`)."""
    return atomic_write(target, lambda tmp: shutil.copyfile(source, tmp), suffix=Path(target).suffix or ".tmp")


@contextlib.contextmanager
def output_set():
    """Stage every atomic write of this thread inside the block; move them all into place when
    it ends, or remove them all on an exception (the previous files stay).  Nested sets join
    the outermost one."""
    if getattr(_STATE, "stage", None) is not None:
        yield
        return
    stage: list = []
    _STATE.stage = stage
    done = False
    try:
        yield
        _STATE.stage = None
        for k, (tmp, target) in enumerate(stage):
            try:
                os.replace(tmp, target)
            except OSError as exc:
                for t, _ in stage[k:]:
                    _unlink(t)
                raise _error(target, exc) from exc
        done = True
    finally:
        _STATE.stage = None
        if not done:
            for tmp, _ in stage:
                _unlink(tmp)


_LOCKS: dict = {}              # (folder, thread id) -> [fd, depth]: re-entrant within a thread
_LOCKS_GUARD = threading.Lock()


def _lock_timeout() -> float:
    try:
        return float(os.environ.get("TABLEAU_LAB_LOCK_TIMEOUT", "600"))
    except ValueError:
        return 600.0


@contextlib.contextmanager
def output_lock(folder, timeout: float | None = None):
    """Hold the advisory lock of output folder ``folder`` (made if missing) for the block: one
    writing process at a time (module docstring).  Waits at most ``timeout`` seconds (default
    ``TABLEAU_LAB_LOCK_TIMEOUT`` or 600), then raises :class:`OutputError`.  Re-entrant within a
    thread.  Without ``fcntl`` (Windows) the block runs unlocked."""
    try:
        import fcntl
    except ImportError:         # pragma: no cover - not POSIX
        yield
        return
    folder = Path(folder)
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise _error(folder, exc, "create") from exc
    key = (os.path.realpath(folder), threading.get_ident())
    with _LOCKS_GUARD:
        held = _LOCKS.get(key)
        if held is not None:
            held[1] += 1
    if held is not None:
        try:
            yield
        finally:
            with _LOCKS_GUARD:
                held[1] -= 1
        return
    path = folder / LOCK_NAME
    deadline = time.monotonic() + (_lock_timeout() if timeout is None else timeout)
    while True:
        try:
            fd = os.open(path, os.O_RDWR | os.O_CREAT | getattr(os, "O_CLOEXEC", 0), 0o666)
        except OSError as exc:
            raise _error(path, exc, "open the lock file") from exc
        try:
            locked = _acquire(fcntl, fd, folder, path, deadline)
            # the holder before us removes the file when it is done: lock the file that is there
            if not locked or _same_file(fd, path):
                break
        except BaseException:
            os.close(fd)
            raise
        os.close(fd)
    try:
        if locked:
            try:
                os.ftruncate(fd, 0)
                os.pwrite(fd, f"{os.getpid()}\n".encode(), 0)
            except OSError:
                pass                    # the holder's id is a courtesy for the messages
        with _LOCKS_GUARD:
            _LOCKS[key] = held = [fd, 1]
        try:
            yield
        finally:
            with _LOCKS_GUARD:
                del _LOCKS[key]
            if locked:
                _unlink(path)           # still holding it: a waiter then sees its file is gone
                with contextlib.suppress(OSError):
                    fcntl.flock(fd, fcntl.LOCK_UN)
    finally:
        os.close(fd)


def _same_file(fd, path) -> bool:
    try:
        a, b = os.fstat(fd), os.stat(path)
    except OSError:
        return False
    return (a.st_dev, a.st_ino) == (b.st_dev, b.st_ino)


def _holder(path) -> str:
    try:
        pid = Path(path).read_text().strip()
        return f"process {pid}" if pid.isdigit() else "another process"
    except OSError:
        return "another process"


def _acquire(fcntl, fd, folder, path, deadline) -> bool:
    """flock(fd) by ``deadline`` (time.monotonic); False on a file system without locks."""
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        return True
    except BlockingIOError:
        pass
    except OSError as exc:
        if exc.errno in (_errno.ENOLCK, _errno.EOPNOTSUPP, _errno.ENOSYS):
            return False                # a file system without locks: unlocked, as documented
        raise _error(path, exc, "lock") from exc
    wait = max(0.0, deadline - time.monotonic())
    print(f"tableau-lab: {folder} is being written by {_holder(path)}; waiting (at most {wait:.3g} s)",
          file=sys.stderr, flush=True)
    delay = 0.02
    while True:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            return True
        except BlockingIOError:
            pass
        if time.monotonic() >= deadline:
            raise OutputError(_errno.EWOULDBLOCK, f"{folder}: still being written by {_holder(path)} "
                                                  f"(lock {path}); try again when it has finished, or write "
                                                  "elsewhere with --out")
        time.sleep(delay)
        delay = min(0.25, delay * 1.5)


_DEFERRING = threading.local()


@contextlib.contextmanager
def deferred_interrupt(note: str = "finishing writing the results; Ctrl-C again to abandon them"):
    """Hold Ctrl-C (SIGINT) for the block: the first is raised as ``KeyboardInterrupt`` when the
    block ends, a second at once.  Only in the main thread, and only when SIGINT raises
    ``KeyboardInterrupt`` (Python's default); otherwise the block runs as it is."""
    if (getattr(_DEFERRING, "on", False) or threading.current_thread() is not threading.main_thread()
            or signal.getsignal(signal.SIGINT) is not signal.default_int_handler):
        yield
        return
    pending = []

    def hold(signum, frame):
        if pending:
            signal.signal(signal.SIGINT, signal.default_int_handler)
            raise KeyboardInterrupt
        pending.append(signum)
        try:
            print(f"tableau-lab: interrupted: {note}", file=sys.stderr, flush=True)
        except (OSError, ValueError):
            pass

    signal.signal(signal.SIGINT, hold)
    _DEFERRING.on = True
    try:
        yield
    finally:
        _DEFERRING.on = False
        signal.signal(signal.SIGINT, signal.default_int_handler)
    if pending:
        raise KeyboardInterrupt


@contextlib.contextmanager
def output_phase(folder, timeout: float | None = None):
    """The write phase of one output folder: its lock, Ctrl-C deferred, stale temporary files
    removed, every atomic write inside staged and moved into place together (module docstring)."""
    with output_lock(folder, timeout), deferred_interrupt():
        remove_stale_temps(folder)
        with output_set():
            yield Path(folder)
