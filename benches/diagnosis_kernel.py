"""The diagnosis's inverse-dynamics kernel against SciPy and its NumPy twin, in one run.

Run: ``python benches/diagnosis_kernel.py`` (a 20 s, 20 000-sample concealed-cogging
record from :mod:`lugre.diagnosis.synth`; best of 20 calls of the core and SciPy, best
of 2 of the NumPy twin).
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import time
import warnings
from typing import Any, Callable

import numpy as np
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
    sigr = R.prepare(rec, model, backend="reference")
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


if __name__ == "__main__":
    main()
