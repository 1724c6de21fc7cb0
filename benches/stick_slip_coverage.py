"""Do the stick-slip intervals of sigma0 and sigma1, with the static step's uncertainty
carried over, hold the truth?

The stick-slip record of ``lugre paper`` (the paper's axis under PID, a 5 mm/s ramp up
and back, 1 um encoder) is fitted with ``lugre.fit_dynamic(..., static_fit=...)`` once
per static data set (``lugre paper``'s design, ``default_rng(seed)``): the record is
the same, only the static step's errors change, which is what the interval of sigma1
must carry. Reported per seed: the estimates, their intervals and verdicts; then how
often each interval held the truth.

    python benches/stick_slip_coverage.py [n_seeds] [first_seed] [static_draws]
"""

from __future__ import annotations

import sys
import time
import warnings

import lugre
import numpy as np
from lugre.paper import static_dataset


def main() -> None:
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 12
    first = int(sys.argv[2]) if len(sys.argv) > 2 else 200
    draws = int(sys.argv[3]) if len(sys.argv) > 3 else 39
    truth = lugre.Model.paper()
    plant = truth.replace(controller={"type": "pid", "kp": 2e4, "ki": 2e4, "kd": 0.0,
                                      "rate_hz": 1e4})
    t = np.arange(0.0, 4.0, 1e-4)
    x_ref = np.where(t < 2.0, 5e-3 * t, 1e-2 - 5e-3 * (t - 2.0))
    r = lugre.simulate(plant, t, x_ref)
    rec = lugre.Recording(t=t, x=np.round(r.x / 1e-6) * 1e-6, i=r.i, x_ref=x_ref)
    hit = {"sigma0": 0, "sigma1": 0}
    det = {"sigma0": 0, "sigma1": 0}
    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for seed in range(first, first + n):
            v, F, _ = static_dataset(np.random.default_rng(seed))
            sfit = lugre.fit_static(v, F)
            start = sfit.to_model(plant).with_friction(sigma0=3e4, sigma1=100.0)
            fit = lugre.fit_dynamic(rec, start, scale_floor=1e-6, static_fit=sfit,
                                    static_draws=draws)
            row = []
            for k in hit:
                tv, est = getattr(truth, k), getattr(fit, k)
                lo, hi = fit.ci95[k]
                hit[k] += lo <= tv <= hi
                det[k] += fit.identifiable[k]
                row.append(f"{k} {est:.5g} ({100 * (est / tv - 1):+.1f} %) [{lo:.4g}, {hi:.4g}]"
                           f" {'determined' if fit.identifiable[k] else 'NOT determined'}")
            print(f"seed {seed}: " + "; ".join(row), flush=True)
    print(f"{n} static data sets ({first}..{first + n - 1}), {draws} static draws, "
          f"{time.perf_counter() - t0:.0f} s")
    for k, held in hit.items():
        print(f"{k}: interval held the truth in {held} of {n}; determined in {det[k]}")


if __name__ == "__main__":
    main()
