"""Cost of a small call through the binding, two installs of ``lugre`` side by side.

Run: ``python benches/binding_overhead.py BEFORE_DIR AFTER_DIR [ROUNDS]``, each
directory holding an installed ``lugre`` package (e.g. a copy of ``site-packages/lugre``
from a build of each commit). The two are timed alternately, round by round, each in a
fresh interpreter with its directory first on ``sys.path``, and the best round of each
is kept (the machine is shared). Calls: ``lugre.fit_static`` on the 48 points of
``../shared/datasets/static/paper_axis_points.csv``, ``lugre.simulate`` of the paper's
axis on 100 samples at 10 kHz, and the binding ``_core.simulate`` alone on the same.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
import warnings
from pathlib import Path

POINTS = Path(__file__).resolve().parents[2] / "shared" / "datasets" / "static" / \
    "paper_axis_points.csv"


def per_call(f, calls: int, repeats: int = 5) -> float:
    """Best over ``repeats`` of the mean time of ``calls`` calls [s]."""
    best = float("inf")
    for _ in range(repeats):
        t0 = time.perf_counter()
        for _ in range(calls):
            f()
        best = min(best, (time.perf_counter() - t0) / calls)
    return best


def worker() -> None:
    import lugre
    import numpy as np
    from lugre import _core

    warnings.simplefilter("ignore")
    v, F = lugre.read_points(POINTS)
    m = lugre.Model.paper()
    t = np.arange(100) * 1e-4
    x_ref = 0.01 * t
    cm = m._core_model()
    out = {
        "where": os.path.dirname(lugre.__file__),
        "fit_static, 48 points": per_call(lambda: lugre.fit_static(v, F), 40),
        "simulate, 100 samples": per_call(lambda: lugre.simulate(m, t, x_ref), 2000),
        "_core.simulate, 100 samples": per_call(
            lambda: _core.simulate(cm, t, "x_ref", x_ref), 2000),
    }
    print(json.dumps(out))


def main() -> None:
    if sys.argv[1:2] == ["--worker"]:
        worker()
        return
    dirs = sys.argv[1:3]
    rounds = int(sys.argv[3]) if len(sys.argv) > 3 else 5
    best: dict[str, dict[str, float]] = {d: {} for d in dirs}
    for _ in range(rounds):
        for d in dirs:
            env = dict(os.environ, PYTHONPATH=d, OPENBLAS_NUM_THREADS="1")
            r = json.loads(subprocess.run([sys.executable, __file__, "--worker"], env=env,
                                          check=True, capture_output=True, text=True,
                                          cwd="/").stdout)
            assert os.path.realpath(r.pop("where")).startswith(os.path.realpath(d)), d
            for k, s in r.items():
                best[d][k] = min(best[d].get(k, float("inf")), s)
    load = os.getloadavg()[0]
    print(f"nproc {os.cpu_count()}, load {load:.2f}, best of {rounds} rounds")
    print(f"{'call':30s} {'before':>12s} {'after':>12s} {'after/before':>13s}")
    for k in best[dirs[0]]:
        a, b = best[dirs[0]][k], best[dirs[1]][k]
        print(f"{k:30s} {a * 1e6:9.1f} us {b * 1e6:9.1f} us {b / a:13.3f}")


if __name__ == "__main__":
    main()
