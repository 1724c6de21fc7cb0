"""Do the presliding experiment's 95 % intervals hold the truth 95 % of the time?

Per seed: the static data set of ``lugre paper`` (24 log-spaced speeds per direction,
0.3 N noise, 12 % gross errors, ``default_rng(seed)``), its IGG fit, then the
presliding record of ``lugre paper`` (open-loop force sweep at standstill up to
0.8 fc, 0.05 N force noise, 50 nm encoder, ``default_rng([seed, 2])``) fitted with
``lugre.presliding.fit_presliding``. Reported: the error of sigma0 and sigma1 (median,
largest), how often each interval holds the truth, and the spread of the estimates
against the reported standard errors (ratio near 1 when the intervals are honest).

    python benches/presliding_coverage.py [n_seeds] [first_seed]
"""

from __future__ import annotations

import sys
import time
import warnings

import lugre
import numpy as np
from lugre.paper import _presliding, static_dataset

TRUTH = lugre.Model.paper()
KEYS = ("sigma0", "sigma1")


def main() -> None:
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 40
    first = int(sys.argv[2]) if len(sys.argv) > 2 else 100
    truth = {"sigma0": TRUTH.sigma0, "sigma1": TRUTH.sigma1}
    err: dict[str, list[float]] = {k: [] for k in KEYS}
    z: dict[str, list[float]] = {k: [] for k in KEYS}
    hit = {k: 0 for k in KEYS}
    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for seed in range(first, first + n):
            v, F, _ = static_dataset(np.random.default_rng(seed))
            pre = _presliding(TRUTH, lugre.fit_static(v, F), np.random.default_rng([seed, 2]))
            row = []
            for k in KEYS:
                est, (lo, hi) = pre.estimate[k], pre.ci95[k]
                err[k].append(est / truth[k] - 1)
                # log-scale z-score: the interval is est * exp(+-q sd)
                sd = np.log(hi / lo) / (2 * 1.96)
                z[k].append(np.log(est / truth[k]) / sd)
                hit[k] += lo <= truth[k] <= hi
                row.append(f"{k} {100 * err[k][-1]:+.3f} % [{lo:.6g}, {hi:.6g}]")
            print(f"seed {seed}: " + "; ".join(row), flush=True)
    print(f"{n} seeds ({first}..{first + n - 1}), {time.perf_counter() - t0:.0f} s")
    for k in KEYS:
        e = np.abs(err[k])
        print(f"{k}: error median {100 * np.median(e):.3f} %, largest {100 * e.max():.3f} %; "
              f"interval held the truth in {hit[k]} of {n} ({100 * hit[k] / n:.0f} %); "
              f"sd of (log error / reported sd at 1.96) {np.std(z[k]):.2f}")


if __name__ == "__main__":
    main()
