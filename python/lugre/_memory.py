"""Memory the allocator keeps after a long record's columns are freed.

A diagnosis of a long record builds and frees hundreds of columns of the record's
length (8 MB each for a million samples). glibc serves them from its heap once the
first is freed and keeps the freed pages resident, so the process's resident size
climbs through the stages even where the bytes in use do not (on a million samples,
about 100 MB over a call). :func:`trim` hands the free pages back between the stages
and trials that free most, at the cost of a walk over the heap (a millisecond or so).
"""

from __future__ import annotations

import ctypes
import ctypes.util
from typing import Any

__all__ = ["trim"]


def _libc_trim() -> Any:
    name = ctypes.util.find_library("c")
    try:
        fn = ctypes.CDLL(name).malloc_trim if name else None
    except (OSError, AttributeError):  # (not glibc: nothing to trim)
        return None
    if fn is not None:
        fn.argtypes, fn.restype = [ctypes.c_size_t], ctypes.c_int
    return fn


_TRIM = _libc_trim()


def trim() -> None:
    """Return the allocator's free pages to the system (glibc's ``malloc_trim``; a
    no-op elsewhere). The numbers computed are not touched."""
    if _TRIM is not None:
        _TRIM(0)
