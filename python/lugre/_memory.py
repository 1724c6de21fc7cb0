"""How many heaps the allocator keeps: at most one per core.

The core runs its batches on a pool of threads (rayon), one per core. glibc gives each
thread that allocates its own heap (arena), up to eight per core, and a heap keeps the
pages of what was freed in it: on a long record, where every column is the record's
length (8 MB for a million samples), each thread's heap holds its own freed columns
and the process's resident size grows with the number of heaps, not with the bytes in
use. One heap per core holds the diagnosis of a million samples at 1 kHz to 948 MiB
where the default reached 1023 MiB, at no cost in time (docs/BENCHMARKS.md); freeing
the pages after every stage, trial and limit (``malloc_trim``) came to 943 MiB and cost
1.4 s a call.

Nothing is changed where the user set ``MALLOC_ARENA_MAX`` or the C library is not
glibc.
"""

from __future__ import annotations

import ctypes
import os

__all__ = ["one_heap_per_core"]

#: ``mallopt``'s parameter for the most arenas (glibc's ``M_ARENA_MAX``).
_M_ARENA_MAX = -8


def one_heap_per_core() -> bool:
    """Cap glibc's arenas at the number of cores; whether it was set."""
    if "MALLOC_ARENA_MAX" in os.environ:
        return False
    try:
        # (the process's own symbols: no search for the library, which can run
        # ldconfig in a subprocess on every import)
        libc = ctypes.CDLL(None)
        libc.gnu_get_libc_version  # noqa: B018  (glibc only)
        mallopt = libc.mallopt
    except (OSError, AttributeError):  # (not glibc: its own allocator)
        return False
    mallopt.argtypes, mallopt.restype = [ctypes.c_int, ctypes.c_int], ctypes.c_int
    return bool(mallopt(_M_ARENA_MAX, max(os.cpu_count() or 1, 1)))
