"""How many heaps the allocator keeps: at most one per core.

The core runs its batches on a pool of threads (rayon), one per core. glibc gives each
thread that allocates its own heap (arena), up to eight per core, and a heap keeps the
pages of what was freed in it: on a long record, where every column is the record's
length (8 MB for a million samples), each thread's heap holds its own freed columns
and the process's resident size grows with the number of heaps, not with the bytes in
use. One heap per core holds the diagnosis of a million samples at 1 kHz to about
950 MiB where the default reached 1000 MiB, at no cost in time (docs/BENCHMARKS.md);
freeing the pages after every stage (``malloc_trim``) came to less and cost a tenth of
the time.

Nothing is changed where the user set ``MALLOC_ARENA_MAX`` or the C library is not
glibc.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import os

__all__ = ["one_heap_per_core"]

#: ``mallopt``'s parameter for the most arenas (glibc's ``M_ARENA_MAX``).
_M_ARENA_MAX = -8


def one_heap_per_core() -> bool:
    """Cap glibc's arenas at the number of cores; whether it was set."""
    if "MALLOC_ARENA_MAX" in os.environ:
        return False
    name = ctypes.util.find_library("c")
    if not name:
        return False
    try:
        libc = ctypes.CDLL(name)
        libc.gnu_get_libc_version  # noqa: B018  (glibc only)
        mallopt = libc.mallopt
    except (OSError, AttributeError):  # (not glibc: its own allocator)
        return False
    mallopt.argtypes, mallopt.restype = [ctypes.c_int, ctypes.c_int], ctypes.c_int
    return bool(mallopt(_M_ARENA_MAX, max(os.cpu_count() or 1, 1)))
