"""Does following ``lugre.design_static`` reach the precision it promises?

Per data set (seeded): a first experiment as in ``lugre paper`` (24 log-spaced speeds
per direction, 2e-4 to 0.4 m/s, Gaussian noise 0.3 N, 12 % of points scaled by
1 +- U(0.1, 0.4)), fitted with IGG; the design from that fit (budget 96 runs per
direction); a second experiment at the designed runs with the same noise and gross-error
process, fitted with IGG on its own. Reported: the worst relative error of the 8 static
parameters, median and 95th percentile, for the first fit, the designed one, the
fit of the designed experiment's clean points alone (oracle: IGG, which on clean points
is least squares on the points it keeps; plain least squares from its single start
lands in a wrong local minimum on some replicated designs), and, for
comparison, 96 log-spaced speeds per direction without design.

    python benches/design_static.py [n_sets] [seed] [target]
"""

from __future__ import annotations

import sys
import time
import warnings

import lugre
import numpy as np
from lugre.paper import static_dataset

TRUTH = lugre.Model.paper()


def worst(fit: lugre.StaticFit) -> float:
    return max(abs(getattr(fit, d).params[k] / getattr(TRUTH, d)[k] - 1)
               for d in ("positive", "negative") for k in ("fc", "fs", "sigma2", "vs"))


def measure(v: np.ndarray, rng: np.random.Generator, noise: float = 0.3,
            share: float = 0.12) -> tuple[np.ndarray, np.ndarray]:
    F = lugre.stribeck(v, TRUTH) + noise * rng.standard_normal(v.size)
    out = rng.uniform(size=v.size) < share
    k = int(out.sum())
    F[out] *= 1 + rng.choice([-1.0, 1.0], size=k) * rng.uniform(0.1, 0.4, size=k)
    return F, out


def main() -> None:
    n_sets = int(sys.argv[1]) if len(sys.argv) > 1 else 200
    seed = int(sys.argv[2]) if len(sys.argv) > 2 else 1
    target = float(sys.argv[3]) if len(sys.argv) > 3 else 0.002
    rng = np.random.default_rng(seed)
    rows: dict[str, list[float]] = {"first (24 log-spaced)": [], "designed": [],
                                    "designed, oracle": [], "96 log-spaced": [],
                                    "96 log-spaced, oracle": []}
    n_points = []
    reached = 0
    t0 = time.perf_counter()
    a96 = np.geomspace(2e-4, 0.4, 96)
    v96 = np.concatenate([a96, -a96])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for _ in range(n_sets):
            v, F, _ = static_dataset(rng)
            first = lugre.fit_static(v, F)
            rows["first (24 log-spaced)"].append(worst(first))
            des = lugre.design_static(first, target=target, budget=96)
            reached += all(des.reached.values())
            vd = des.points()
            n_points.append(max(int(des.repeats[d].sum()) for d in ("positive", "negative")))
            Fd, out = measure(vd, rng)
            rows["designed"].append(worst(lugre.fit_static(vd, Fd)))
            rows["designed, oracle"].append(
                worst(lugre.fit_static(vd[~out], Fd[~out])))
            Fu, outu = measure(v96, rng)
            rows["96 log-spaced"].append(worst(lugre.fit_static(v96, Fu)))
            rows["96 log-spaced, oracle"].append(
                worst(lugre.fit_static(v96[~outu], Fu[~outu])))
    print(f"{n_sets} data sets, seed {seed}, target {100 * target:.2g} % relative standard "
          f"error, budget 96 runs per direction; {time.perf_counter() - t0:.1f} s")
    print(f"designed runs per direction: median {np.median(n_points):.0f}, max "
          f"{max(n_points)}; target reached in both directions in {reached} of {n_sets}")
    print(f"{'':26s} {'median':>8s} {'p95':>8s}   (worst relative parameter error)")
    for k, e in rows.items():
        print(f"{k:26s} {100 * np.median(e):7.2f} % {100 * np.percentile(e, 95):7.2f} %")


if __name__ == "__main__":
    main()
