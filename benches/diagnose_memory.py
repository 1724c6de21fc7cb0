"""Memory of `lugre.diagnosis.diagnose` stage by stage: the RSS at each stage's end, its
peak (sampled every 2 ms) and, with glibc, the peak of the allocator's bytes in use
(`mallinfo2`, every 5 ms):

    python -c "import pickle; from lugre.diagnosis.synth import concealed; \
        r, m, _ = concealed('cogging', duration=1000.0); pickle.dump((r, m), open('/tmp/r1m.pkl', 'wb'))"
    PYTHONPATH=python python benches/diagnose_memory.py /tmp/r1m.pkl
"""

from __future__ import annotations

import ctypes
import functools
import pickle
import resource
import sys
import threading
import time
from typing import Any

from lugre.diagnosis import core

STAGES = ("prepare", "question", "weigh", "select", "release_columns", "refit", "gather",
          "assemble", "far_base")


class _Mallinfo2(ctypes.Structure):
    _fields_ = [(n, ctypes.c_size_t) for n in ("arena", "ordblks", "smblks", "hblks",
                                               "hblkhd", "usmblks", "fsmblks", "uordblks",
                                               "fordblks", "keepcost")]


def _in_use() -> Any:
    """Bytes the allocator has handed out [MB], or None without glibc's mallinfo2."""
    try:
        libc = ctypes.CDLL("libc.so.6")
        libc.mallinfo2.restype = _Mallinfo2
    except (OSError, AttributeError):
        return None

    def read() -> float:
        x = libc.mallinfo2()
        return (x.uordblks + x.hblkhd) / 1e6
    return read


def _rss() -> float:
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * resource.getpagesize() / 1e6


class _Sampler(threading.Thread):
    def __init__(self) -> None:
        super().__init__(daemon=True)
        self.in_use = _in_use()
        self.rss = self.used = 0.0
        self.stop = False

    def reset(self) -> None:
        self.rss = self.used = 0.0

    def run(self) -> None:
        while not self.stop:
            self.rss = max(self.rss, _rss())
            if self.in_use is not None:
                self.used = max(self.used, self.in_use())
            time.sleep(0.002)


def _watch(sampler: _Sampler, name: str) -> None:
    f = getattr(core, name)

    @functools.wraps(f)
    def stage(*a: Any, **k: Any) -> Any:
        sampler.reset()
        t = time.perf_counter()
        out = f(*a, **k)
        used = f", in use peak {sampler.used:6.0f} MB" if sampler.in_use else ""
        print(f"{name:16s} RSS at end {_rss():6.0f} MB, peak {sampler.rss:6.0f} MB{used}; "
              f"{time.perf_counter() - t:6.1f} s", flush=True)
        return out
    setattr(core, name, stage)


def main() -> None:
    with open(sys.argv[1], "rb") as f:
        rec, model = pickle.load(f)
    sampler = _Sampler()
    sampler.start()
    for name in STAGES:
        _watch(sampler, name)
    t = time.perf_counter()
    core.diagnose(rec, model)
    sampler.stop = True
    print(f"call {time.perf_counter() - t:.1f} s, peak RSS of the process "
          f"{resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.0f} MiB")


if __name__ == "__main__":
    main()
