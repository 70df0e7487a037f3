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

**One guarded way to write** (issue 29): every output path passes :func:`guard_output` — before
the work (a command's known outputs, :func:`refuse_outputs`) and again in :func:`atomic_write`.
It refuses, with an :class:`OutputRefused` naming the path and why (the CLI: exit 2, nothing
written):

* a path outside the folder the user named: inside ``output_phase(folder)`` every write and
  every nested phase must resolve (symbolic links followed) inside ``folder``; names that come
  from data go through :func:`output_name` (no ``/``, no ``..``, no absolute path, no empty name);
* anything but a regular file at the target: a directory, a FIFO, a device node, a socket, and a
  symbolic link (replacing it would not write where it points, and writing there would leave the
  folder);
* an input of the command: the same file (same device and inode: hard links and symbolic links
  included) as a file given on the command line or read during the command (:func:`note_input`,
  called by every bounded reader inside :func:`command_inputs`);
* a file the command did not make, where the caller says what its own files look like (``mine``:
  a design checkpoint, a saved tableau);
* a name longer than ``NAME_MAX`` bytes.

**One bounded way to read**: JSON through :func:`tableau_lab.inputs.read_json` (at most its
``max_bytes``), saved arrays through :func:`load_npz` (at most :data:`MAX_NPZ_BYTES` on the disk
and :data:`MAX_NPZ_UNPACKED` decompressed, checked from the members' headers before anything is
decompressed), design checkpoints at most :data:`MAX_CHECKPOINT_BYTES`.
"""
from __future__ import annotations

import contextlib
import errno as _errno
import os
import re
import secrets
import shutil
import signal
import stat
import sys
import threading
import time
from pathlib import Path

from .inputs import NAME_MAX, command_inputs, note_input, printable, recorded_inputs
from .process import alive

__all__ = ["atomic_write", "atomic_write_text", "atomic_copy", "OutputError", "output_set", "output_lock",
           "output_phase", "deferred_interrupt", "remove_stale_temps", "is_temp", "TEMP_PATTERN", "LOCK_NAME",
           "OutputRefused", "guard_output", "refuse_outputs", "output_name", "note_input", "command_inputs",
           "path_exists", "load_npz", "lock_timeout", "NAME_MAX", "MAX_NPZ_BYTES", "MAX_NPZ_UNPACKED",
           "MAX_CHECKPOINT_BYTES"]

MAX_NPZ_BYTES = 256 * 2 ** 20     # a saved data.npz read back (replot): its size on the disk …
MAX_NPZ_UNPACKED = 256 * 2 ** 20  # … and its arrays decompressed (every member's header checked first)
MAX_CHECKPOINT_BYTES = 32 * 2 ** 20   # a design checkpoint read back (experiments/design_search.py)
LOCK_TIMEOUT = 600.0              # default seconds a writer waits for an output folder's lock

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


class OutputRefused(OutputError):
    """An output path the guard refuses (:func:`guard_output`): an input of the command, outside
    the output folder, not a regular file, or a file the command did not make.  Nothing is
    written; the message names the path (and the input it would replace)."""

    def __init__(self, message: str):
        super().__init__(_errno.EPERM, message)


_KINDS = ((stat.S_ISLNK, "a symbolic link"), (stat.S_ISDIR, "a directory"), (stat.S_ISFIFO, "a FIFO (named pipe)"),
          (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"), (stat.S_ISSOCK, "a socket"))


def _shown(path) -> str:
    return printable(os.fspath(path))


def path_exists(path) -> bool:
    """``os.path.exists`` that says False, not raises, for a name the system refuses (longer than
    ``NAME_MAX``, a NUL byte)."""
    try:
        os.stat(path)
        return True
    except (OSError, ValueError):
        return False


def _long_part(path) -> str | None:
    for part in Path(path).parts:
        if len(os.fsencode(part)) > NAME_MAX:
            return part
    return None


def derived_name(*parts, fill: str = "_", default: str = "output") -> str:
    """An output file name made of user-given parts (a method file's stem, a problem or family
    name): each run of characters outside ``A-Za-z0-9_.-`` made one ``fill``, the ends stripped of
    ``- _ .``, at most ``inputs.NAME_LENGTH`` characters; ``default`` when nothing is left.

    >>> derived_name("roundoff", "../my method", "mp:32")
    'roundoff_.._my_method_mp_32'
    >>> derived_name("bdf:4", fill="-"), derived_name(":::", default="method")
    ('bdf-4', 'method')
    """
    from .inputs import NAME_LENGTH, SAFE_NAME
    name = re.sub(r"[^A-Za-z0-9_.-]+", fill, "_".join(map(str, parts))).strip("-_.")[:NAME_LENGTH].rstrip("-_.")
    return name if SAFE_NAME.fullmatch(name) else default


def output_name(name, source, what: str = "name") -> str:
    """``name``, read from ``source`` (a data file), as one file name inside an output folder: ASCII
    letters, digits, ``- _ .``, starting with a letter or digit, at most 100 characters (so never
    empty, ``.``, ``..``, a path or absolute).  Otherwise :class:`~tableau_lab.errors.InputError`
    naming the source and the key.

    >>> output_name("wp_kepler", "data.json")
    'wp_kepler'
    >>> output_name("../../x", "data.json")  # doctest: +NORMALIZE_WHITESPACE
    Traceback (most recent call last):
    ...
    tableau_lab.errors.InputError: data.json: name: '../../x' is not a file name (ASCII letters, digits,
    - _ . starting with a letter or digit, at most 100 characters)
    """
    from .errors import InputError
    from .inputs import NAME_LENGTH, SAFE_NAME
    if not isinstance(name, str) or not SAFE_NAME.fullmatch(name):
        raise InputError(f"{printable(source)}: {what}: {printable(repr(name))[:120]} is not a file name (ASCII "
                         f"letters, digits, - _ . starting with a letter or digit, at most {NAME_LENGTH} characters)")
    return name


def _same(st, path) -> bool:
    try:
        other = os.stat(path)
    except (OSError, ValueError, TypeError):
        return False
    return (st.st_dev, st.st_ino) == (other.st_dev, other.st_ino)


def _inside(path, root) -> bool:
    real, root = os.path.realpath(path), os.path.realpath(root)
    return real == root or real.startswith(root.rstrip(os.sep) + os.sep)


def guard_output(target, *, within=None, inputs=(), mine=None, what: str = "output") -> Path:
    """``target`` as a path this command may write (module docstring), else :class:`OutputRefused`.

    ``within``: the folder it must stay in (default: the folder of the enclosing
    :func:`output_phase`, if any); ``inputs``: more input files besides the command's recorded
    ones; ``mine(path) -> bool``: whether an existing file is one the command made (it is replaced
    only then); ``what``: the output's name in the message (e.g. ``"--checkpoint"``)."""
    target = Path(target)
    shown = _shown(target)
    long = _long_part(target)
    if long is not None:
        raise OutputRefused(f"{shown[:80]}…: {what}: a file name of {len(os.fsencode(long))} bytes is longer than "
                            f"the system's limit of {NAME_MAX}")
    if target.name in ("", ".", ".."):
        raise OutputRefused(f"{shown}: {what}: not a file name")
    roots = getattr(_STATE, "roots", None) or []
    for root in ([within] if within is not None else roots[-1:]):
        if not _inside(target, root):
            raise OutputRefused(f"{shown}: {what}: outside the output folder {_shown(root)}; not written")
    try:
        st = os.lstat(target)
    except FileNotFoundError:
        return target
    except (OSError, ValueError) as exc:
        raise OutputRefused(f"{shown}: {what}: cannot be written: {getattr(exc, 'strerror', None) or exc}") from None
    try:
        followed = os.stat(target)          # a symbolic link: the file it points to
    except (OSError, ValueError):
        followed = st
    for p in list(inputs) + recorded_inputs():
        if _same(followed, p):
            raise OutputRefused(f"{shown}: {what} would overwrite the input {_shown(p)} (the same file); nothing "
                                "written: choose another output name or folder")
    kind = next((k for test, k in _KINDS if test(st.st_mode)), None if stat.S_ISREG(st.st_mode) else "not a file")
    if kind:
        raise OutputRefused(f"{shown}: {what}: {kind} is there; tableau-lab writes only regular files it made "
                            "(nothing written): remove it or choose another name")
    if mine is not None and not mine(target):
        raise OutputRefused(f"{shown}: {what}: the file there was not made by this command; not replaced "
                            "(remove it or choose another name)")
    return target


def refuse_outputs(outputs, inputs=(), *, within=None, mine=None, what: str = "output") -> list:
    """:func:`guard_output` of each of ``outputs`` before any work: the outputs a command will
    write, checked against its ``inputs`` (and the recorded ones).  Returns the paths."""
    return [guard_output(o, within=within, inputs=inputs, mine=mine, what=what) for o in outputs]


def load_npz(path, error, what: str = "saved data file") -> dict:
    """The arrays of a ``.npz`` file written by ``numpy.savez[_compressed]``, read bounded: a
    regular file of at most :data:`MAX_NPZ_BYTES`, whose members' ``.npy`` headers (read before
    any array) declare plain (no object) arrays of at most :data:`MAX_NPZ_UNPACKED` bytes in all,
    each member's zip entry no larger than its array.  Otherwise ``error`` (a class) with a
    message naming the file and the member."""
    import zipfile

    import numpy as np
    from numpy.lib import format as npformat
    shown = printable(os.fspath(path))
    try:
        st = os.stat(path)
    except (OSError, ValueError) as exc:
        raise error(f"{shown}: cannot read: {getattr(exc, 'strerror', None) or exc}") from None
    if not stat.S_ISREG(st.st_mode):
        raise error(f"{shown}: not a regular file, not a {what}")
    if st.st_size > MAX_NPZ_BYTES:
        raise error(f"{shown}: file is {st.st_size} bytes, larger than the {MAX_NPZ_BYTES}-byte limit for a {what}")
    note_input(path)
    arrays, total = {}, 0
    try:
        with zipfile.ZipFile(path) as zf:
            infos = zf.infolist()
            for info in infos:
                total += info.file_size
                if total > MAX_NPZ_UNPACKED:
                    raise error(f"{shown}: {info.filename}: decompresses to more than the {MAX_NPZ_UNPACKED}-byte "
                                f"limit for a {what}")
            for info in infos:
                name = info.filename
                if not name.endswith(".npy"):
                    raise error(f"{shown}: {printable(name)}: not an array member (.npy) of a {what}")
                with zf.open(info) as fh:
                    version = npformat.read_magic(fh)
                    if version not in ((1, 0), (2, 0)):
                        raise error(f"{shown}: {printable(name)}: .npy format {version} is not one numpy.savez writes")
                    header = npformat.read_array_header_1_0 if version == (1, 0) else npformat.read_array_header_2_0
                    shape, _, dtype = header(fh)
                    if dtype.hasobject:
                        raise error(f"{shown}: {printable(name)}: an object array; only numbers are read")
                    size = int(np.prod(shape, dtype=object)) * dtype.itemsize
                    if size > info.file_size:
                        raise error(f"{shown}: {printable(name)}: its header declares {size} bytes, more than the "
                                    f"member holds ({info.file_size}): damaged")
            with np.load(path, allow_pickle=False) as z:
                for k in z.files:
                    arrays[k] = z[k]
    except (OSError, ValueError, EOFError, zipfile.BadZipFile, KeyError, RuntimeError) as exc:
        if isinstance(exc, error):
            raise
        raise error(f"{shown}: not a readable {what} ({type(exc).__name__}: {printable(str(exc))[:160]})") from None
    return arrays


def is_temp(name: str) -> bool:
    """Whether a file name is one of our temporary files (of any process, alive or not)."""
    return bool(TEMP_PATTERN.match(name))


def remove_stale_temps(folder) -> list:
    """Remove the temporary files in ``folder`` left by processes that are gone (killed while
    writing); returns the names removed.  Temporary files of live processes are kept."""
    removed: list[str] = []
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
    target = guard_output(target)               # the one guard: in the folder, not an input, a regular file
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


def lock_timeout() -> float:
    """Seconds a writer waits for a busy output folder: ``TABLEAU_LAB_LOCK_TIMEOUT`` (a finite
    number ≥ 0; anything else is refused with :class:`~tableau_lab.errors.InputError`), default
    :data:`LOCK_TIMEOUT`.

    >>> os.environ["TABLEAU_LAB_LOCK_TIMEOUT"] = "nan"
    >>> lock_timeout()  # doctest: +NORMALIZE_WHITESPACE
    Traceback (most recent call last):
    ...
    tableau_lab.errors.InputError: TABLEAU_LAB_LOCK_TIMEOUT='nan': not a number of seconds
    (a finite number ≥ 0, e.g. 600)
    >>> del os.environ["TABLEAU_LAB_LOCK_TIMEOUT"]
    """
    import math

    from .errors import InputError
    text = os.environ.get("TABLEAU_LAB_LOCK_TIMEOUT")
    if text is None or not text.strip():
        return LOCK_TIMEOUT
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and value >= 0):
        raise InputError(f"TABLEAU_LAB_LOCK_TIMEOUT={printable(repr(text))[:60]}: not a number of seconds (a finite "
                         "number ≥ 0, e.g. 600)")
    return value


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
    deadline = time.monotonic() + (lock_timeout() if timeout is None else timeout)
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
    pending: list[int] = []

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
    removed, every atomic write inside staged and moved into place together (module docstring).
    Every write inside, and every nested phase, must stay inside ``folder`` (:func:`guard_output`);
    a nested phase's folder is checked before it is made."""
    with confined(folder), output_lock(folder, timeout), deferred_interrupt():
        remove_stale_temps(folder)
        with output_set():
            yield Path(folder)


@contextlib.contextmanager
def confined(folder):
    """Inside the block every :func:`guard_output` (so every atomic write) must resolve inside
    ``folder``, itself inside the enclosing confinement if any (checked first: nothing is made
    outside)."""
    roots = getattr(_STATE, "roots", None)
    if roots is None:
        roots = _STATE.roots = []
    if roots and not _inside(folder, roots[-1]):
        raise OutputRefused(f"{_shown(folder)}: outside the output folder {_shown(roots[-1])}; nothing written there")
    long = _long_part(folder)
    if long is not None:
        raise OutputRefused(f"{_shown(folder)[:80]}…: a folder name of {len(os.fsencode(long))} bytes is longer than "
                            f"the system's limit of {NAME_MAX}")
    roots.append(os.path.realpath(folder))
    try:
        yield
    finally:
        roots.pop()
