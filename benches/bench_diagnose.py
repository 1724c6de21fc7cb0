"""Time a diagnosis of a 20,000-sample recording (one thread), and print the result.

Run: ``OPENBLAS_NUM_THREADS=1 python benches/bench_diagnose.py [RECORDING MODEL]``
(default: a 20 s concealed-cogging recording from :mod:`lugre.diagnosis.synth`).
"""

from __future__ import annotations

import os
import sys
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import lugre
from lugre.diagnosis import diagnose
from lugre.diagnosis.synth import concealed


def main() -> None:
    if len(sys.argv) == 3:
        rec, model = lugre.read_recording(sys.argv[1]), lugre.load_model(sys.argv[2])
    else:
        rec, model, _ = concealed("cogging", duration=20.0)
    best = float("inf")
    for _ in range(3):
        t0 = time.perf_counter()
        dg = diagnose(rec, model, closed_loop=False)
        best = min(best, time.perf_counter() - t0)
    print(f"{len(rec)} samples: diagnose {best:.2f} s (best of 3, closed loop off)")
    t0 = time.perf_counter()
    diagnose(rec, model)
    print(f"with closed-loop simulation: {time.perf_counter() - t0:.2f} s")
    print(dg.summary())


if __name__ == "__main__":
    main()
