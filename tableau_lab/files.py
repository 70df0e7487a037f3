"""Atomic file writes, for every layer: a file is either its old self or wholly new, never
half-written (a temporary file beside the target, then ``os.replace``)."""
from __future__ import annotations

import os
import tempfile
from pathlib import Path

__all__ = ["atomic_write", "atomic_write_text"]


def atomic_write(target, write, suffix: str = ".tmp") -> Path:
    """Call ``write(temporary_path)``, then move the result onto ``target`` (its folder is made).
    ``suffix`` is the temporary file's ending, for writers that choose the format by it."""
    target = Path(target)
    target.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=target.parent, prefix=f".{target.name}.", suffix=suffix)
    os.close(fd)
    umask = os.umask(0)
    os.umask(umask)
    try:
        write(tmp)
        os.chmod(tmp, 0o666 & ~umask)          # as an ordinary file (mkstemp makes it private)
        os.replace(tmp, target)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
    return target


def atomic_write_text(target, text: str) -> Path:
    return atomic_write(target, lambda tmp: Path(tmp).write_text(text, encoding="utf-8"))
