"""Throughput of lugre fleet run on 1 and on 2 workers, on the same generated fleet, in one
run (tests/fleetgen.py: 20 axes, 10 nights, 3 s records at 1 kHz):

    PYTHONPATH=python python benches/fleet_bench.py [--out DIR] [--axes 20] [--nights 10]

Each run starts its own local cluster and a fresh history; the time counted is the run's
(discovery, cluster start, diagnoses, stores). The ratio is the 2-worker throughput over
the 1-worker one.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

import fleetgen  # (tests/ holds the fleet generator)
from lugre.fleet import run


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", help="folder for the fleet and histories (default: a temp one)")
    ap.add_argument("--axes", type=int, default=fleetgen.AXES)
    ap.add_argument("--nights", type=int, default=fleetgen.NIGHTS)
    a = ap.parse_args()
    out = Path(a.out or tempfile.mkdtemp(prefix="fleet-bench-"))
    fleet = fleetgen.write_fleet(out / "plant", nights=a.nights, axes=a.axes, corrupt=False)
    n = len(fleet.recordings)
    print(f"{n} recordings of {len(fleet.axes)} axes in {fleet.root}; {os.cpu_count()} cores; "
          f"load average before: {', '.join(f'{x:.1f}' for x in os.getloadavg())}")
    rates = {}
    for workers in (1, 2):
        db = out / f"fleet-{workers}.duckdb"
        if db.exists():
            db.unlink()
        t0 = time.perf_counter()
        s = run(fleet.root, db, workers=workers)
        dt = time.perf_counter() - t0
        assert s.stored == n and not s.errors, s.text()
        rates[workers] = n / dt
        print(f"{workers} worker(s): {dt:.1f} s, {rates[workers]:.2f} recordings/s")
    print(f"2 workers / 1 worker: {rates[2] / rates[1]:.2f}x; load average after: "
          f"{', '.join(f'{x:.1f}' for x in os.getloadavg())}")


if __name__ == "__main__":
    main()
