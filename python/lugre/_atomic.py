"""Atomic file writes: the destination is written whole or not at all."""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

__all__ = ["atomic_write"]

#: Where ``-`` is written (None: ``sys.stdout``); the command line sets it while its
#: own lines go to standard error.
STDOUT = None


def _write_through(path: str | os.PathLike[str], data: bytes) -> bool:
    """Write ``data`` through to standard output (``-``) or to an existing file that is
    not a regular one (a device such as ``/dev/null``, a FIFO, a socket): such a path is
    never replaced. True when written so."""
    import stat
    import sys

    if os.fspath(path) == "-":
        stream = STDOUT if STDOUT is not None else sys.stdout
        out = getattr(stream, "buffer", None)
        if out is None:
            stream.write(data.decode("utf-8"))
        else:
            stream.flush()
            out.write(data)
        stream.flush()
        return True
    try:
        mode = os.stat(path).st_mode
    except (FileNotFoundError, NotADirectoryError):
        return False
    if stat.S_ISREG(mode) or stat.S_ISDIR(mode):
        return False
    with open(path, "wb") as fh:
        fh.write(data)
    return True


def atomic_write(path: str | os.PathLike[str], data: bytes) -> None:
    """Write ``data`` to ``path`` whole or not at all.

    The bytes go to a temporary file in the destination's directory, are flushed to
    disk, and the temporary file then replaces ``path`` (:func:`os.replace` is atomic
    within one file system). On any error the temporary file is removed and ``path`` is
    left as it was. ``-`` (standard output), a device, a FIFO or another special file is
    written through, never replaced (``--json /dev/null`` throws the output away).
    """
    if _write_through(path, data):
        return
    dest = Path(path)
    directory = dest.parent if str(dest.parent) else Path(".")
    if not directory.is_dir():
        raise FileNotFoundError(
            2, f"cannot write {os.fspath(path)}: the directory {os.fspath(directory)} does "
            "not exist: create it first or choose another path", os.fspath(path))
    if dest.is_dir():
        raise IsADirectoryError(
            21, f"cannot write {os.fspath(path)}: it is a directory: give a file name",
            os.fspath(path))
    try:
        fd, tmp = tempfile.mkstemp(dir=directory, prefix=f".{dest.name}.", suffix=".tmp")
    except PermissionError:
        raise PermissionError(
            13, f"cannot write {os.fspath(path)}: no permission to create files in "
            f"{os.fspath(directory)}: choose another directory", os.fspath(path)) from None
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
        try:
            mode = os.stat(dest).st_mode & 0o777
        except FileNotFoundError:
            umask = os.umask(0)
            os.umask(umask)
            mode = 0o666 & ~umask
        os.chmod(tmp, mode)
        os.replace(tmp, dest)
    except BaseException:
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass
        raise


_atomic_write = atomic_write
