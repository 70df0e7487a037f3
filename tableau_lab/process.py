"""Process hygiene shared by the layers: a child process that must not outlive its parent.

>>> callable(die_with_parent)
True
"""
from __future__ import annotations

import contextlib
import os
import shutil
import signal
import sys
import tempfile
from pathlib import Path

__all__ = ["die_with_parent", "alive", "start_time", "scratch_folder"]


def die_with_parent() -> bool:
    """Ask the kernel to SIGKILL this process when its parent dies (Linux ``prctl(PR_SET_PDEATHSIG)``);
    False where that is not available (the caller then watches its parent itself)."""
    if not sys.platform.startswith("linux"):
        return False
    with contextlib.suppress(Exception):
        import ctypes
        PR_SET_PDEATHSIG = 1
        return ctypes.CDLL(None, use_errno=True).prctl(PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0) == 0
    return False


def _stat(pid: int) -> list:
    """The fields of /proc/PID/stat after the command name (state first; start time at 19)."""
    with open(f"/proc/{pid}/stat", "rb") as f:
        return f.read().rpartition(b")")[2].split()


def start_time(pid: int):
    """The start time of process ``pid`` (clock ticks since boot, Linux), None elsewhere or if
    gone: with the pid it names one process (pids are reused)."""
    try:
        return int(_stat(pid)[19])
    except (OSError, ValueError, IndexError):
        return None


def alive(pid: int, started: int | None = None) -> bool:
    """Whether process ``pid`` runs on this machine (a zombie counts as gone); with ``started``
    (its start time, field 22 of /proc/PID/stat) also that it is the same process, not a new one
    that got its pid."""
    if pid == os.getpid():
        return True
    if pid <= 0:
        return False
    try:
        fields = _stat(pid)
        return fields[0] not in (b"Z", b"X") and (started is None or int(fields[19]) == started)
    except FileNotFoundError:
        return False
    except (OSError, ValueError, IndexError):     # no /proc: ask the kernel
        pass
    try:
        os.kill(pid, 0)
    except (ProcessLookupError, OverflowError):
        return False
    except OSError:                                 # PermissionError: it exists
        pass
    return True


def scratch_folder(prefix: str):
    """A temporary folder ``<tmp>/<prefix><pid>_…`` for this process (a TemporaryDirectory);
    the folders of that prefix left by processes that are gone (killed) are removed first."""
    for d in Path(tempfile.gettempdir()).glob(f"{prefix}*_*"):
        pid = d.name[len(prefix):].split("_", 1)[0]
        if pid.isdigit() and not alive(int(pid)):
            shutil.rmtree(d, ignore_errors=True)
    return tempfile.TemporaryDirectory(prefix=f"{prefix}{os.getpid()}_")
