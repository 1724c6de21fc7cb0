"""The diagnosis's inverse-dynamics kernel against SciPy and its NumPy twin, in one run.

Run: ``python benches/diagnosis_kernel.py`` (a 20 s, 20 000-sample concealed-cogging
record from :mod:`lugre.diagnosis.synth`; best of 20 calls of the core and SciPy, best
of 2 of the NumPy twin). The last lines: the periodogram over position
(``position_sums``, the cogging pitch search and the localisation) in the core against
the NumPy outer products it replaced and against its twin.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import time
import warnings
from typing import Any, Callable

import numpy as np
from lugre import reference
from lugre.diagnosis import residual as R
from lugre.diagnosis.synth import concealed
from scipy import signal

NAMES = ["positive.fc", "positive.fs", "positive.sigma2", "positive.vs", "negative.fc",
         "negative.fs", "negative.sigma2", "negative.vs", "sigma0", "sigma1"]


def best(f: Callable[[], Any], n: int) -> float:
    b = float("inf")
    for _ in range(n):
        t = time.perf_counter()
        f()
        b = min(b, time.perf_counter() - t)
    return b


def main() -> None:
    warnings.simplefilter("ignore")
    rec, model, _ = concealed("cogging", duration=20.0)
    sig = R.prepare(rec, model)
    sigr = R.prepare(rec, model, backend=reference.kernels)
    y = np.random.default_rng(0).standard_normal(len(sig))
    sos = signal.butter(4, sig.cutoff_hz / (0.5 * sig.fs), output="sos")
    res = model.replace(effects=[{"effect": "resonance", "frequency": 22.0,
                                  "damping_ratio": 0.04, "load_fraction": 0.75}])
    rows = [
        ("low-pass (filtfilt, order 4)", lambda: sig.kernel.filt(y),
         lambda: signal.sosfiltfilt(sos, y, padtype="odd", padlen=72),
         lambda: sigr.kernel.filt(y)),
        ("residual, plain model", lambda: sig.kernel.residual(model), None,
         lambda: sigr.kernel.residual(model)),
        ("residual, with a resonance", lambda: sig.kernel.residual(res), None,
         lambda: sigr.kernel.residual(res)),
        ("sensitivities, 10 parameters", lambda: sig.kernel.base_sensitivities(model, NAMES),
         None, lambda: sigr.kernel.base_sensitivities(model, NAMES)),
    ]
    print(f"{len(sig)} samples")
    for name, core, sp, twin in rows:
        tc = best(core, 20)
        ts = best(sp, 20) if sp else None
        tt = best(twin, 2)
        line = f"{name}: core {tc * 1e3:.2f} ms"
        if ts is not None:
            line += f", SciPy {ts * 1e3:.2f} ms ({ts / tc:.1f}x)"
        print(line + f", NumPy twin {tt * 1e3:.0f} ms ({tt / tc:.0f}x)")
    models = [model.replace(effects=[{"effect": "resonance", "frequency": float(f),
                                      "damping_ratio": 0.04, "load_fraction": 0.75}])
              for f in np.geomspace(5.0, 30.0, 16)]
    t1 = best(lambda: [sig.kernel.residual(m) for m in models], 3)
    t2 = best(lambda: sig.kernel.residuals(models), 3)
    print(f"16 resonance residuals: one by one {t1 * 1e3:.0f} ms, batch {t2 * 1e3:.0f} ms "
          f"({t1 / t2:.2f}x)")
    periodogram(sig, model)


def periodogram(sig: R.Signals, model: Any) -> None:
    """``position_sums`` as the cogging search calls it: every 3rd sample of the record
    (6 667), the spatial frequencies of its pitch grid, with the squares."""
    from lugre import reference
    from lugre._native import position_sums

    r = sig.kernel.residual(model)
    x = sig.x[sig.mask][::3]
    rr = r[sig.mask][::3] - np.mean(r[sig.mask])
    span = float(np.ptp(x))
    ks = np.arange(1.5 / span, 545 * 0.25 / span, 0.25 / span)

    def outer() -> None:  # the NumPy code of Cogging._power before the kernel
        for j in range(0, ks.size, 200):
            ph = 2.0 * np.pi * np.outer(ks[j:j + 200], x)
            s, c = np.sin(ph), np.cos(ph)
            (s * s).sum(1), (c * c).sum(1), (s * c).sum(1)
            np.einsum("ij,j->i", s, rr), np.einsum("ij,j->i", c, rr)

    args = (x, rr, float(ks[0]), 0.25 / span, ks.size)
    tn = best(outer, 5)
    tc = best(lambda: position_sums(*args, squares=True), 20)
    tt = best(lambda: reference.position_sums(*args, squares=True), 3)
    tc2 = best(lambda: position_sums(*args), 20)
    print(f"periodogram, {x.size} samples x {ks.size} frequencies: core {tc * 1e3:.2f} ms "
          f"(without the squares {tc2 * 1e3:.2f} ms), NumPy outer products "
          f"{tn * 1e3:.1f} ms ({tn / tc:.0f}x), NumPy twin {tt * 1e3:.1f} ms")


if __name__ == "__main__":
    main()
