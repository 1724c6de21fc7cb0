"""Score `lugre fit` on the cases of benches/fit_cases.py: the fitted model's held-out
force nrmse against the true model's, its parameters against the truth, and how many
of its 95 % intervals hold the truth.

    python benches/fit_score.py CASES_DIR [--json OUT.json]
"""

from __future__ import annotations

import argparse
import json
import time
import warnings
from pathlib import Path

import lugre
import numpy as np
from lugre.diagnosis import evaluate
from lugre.diagnosis.basefit import identify

PARAMS = ("fc", "fs", "vs", "sigma2")


def score(d: Path) -> dict:
    truth = json.loads((d / "truth.json").read_text())
    setup = truth.pop("setup")
    mt = lugre.Model(truth)
    rec = lugre.read_recording(d / "recording.csv")
    hold = lugre.read_recording(d / "holdout.csv")
    t0 = time.perf_counter()
    res = identify(rec, force_constant=truth["axis"]["force_constant"])
    took = time.perf_counter() - t0
    fm = res.model
    out = {"case": d.name, **{k: setup[k] for k in ("trajectory", "rate_hz")},
           "loop": truth["controller"]["type"], "mass_true": truth["axis"]["mass"],
           "seconds": took,
           "true": evaluate(hold, mt)["nrmse_force"], "fitted": evaluate(hold, fm)["nrmse_force"]}
    out["ratio"] = out["fitted"] / out["true"]
    errs = {"mass": (fm.mass / mt.mass - 1, res.profiles.get("mass", {}).get("determined"))}
    for side in ("positive", "negative"):
        for k in PARAMS:
            key = f"{side}.{k}"
            pk = {"fs": f"{side}.hump"}.get(k, key)
            det = res.profiles.get(pk, {}).get("determined")
            errs[key] = (fm.friction[side][k] / mt.friction[side][k] - 1, det)
    out["errors"] = errs
    out["covered"] = _covered(res.profiles, mt)
    return out


def _true_value(mt: lugre.Model, name: str) -> float | None:
    """The true value of a fitted parameter's name (``positive.hump``: fs - fc)."""
    if name == "mass":
        return mt.mass
    side, _, k = name.partition(".")
    if side in ("positive", "negative"):
        f = mt.friction[side]
        return f["fs"] - f["fc"] if k == "hump" else f.get(k)
    return mt.friction.get(name)


def _covered(profiles: dict, mt: lugre.Model) -> dict[str, tuple[bool, str, float]]:
    """Per parameter with a two-sided interval: whether it holds the truth, how the
    interval was had (``wald`` or ``profile``), and the truth's distance from the value
    in half-widths of the interval on its side (1: at the interval's end)."""
    out = {}
    for name, p in profiles.items():
        ci, true, val = p.get("ci95"), _true_value(mt, name), p.get("value")
        if not ci or ci[0] is None or ci[1] is None or true is None or val is None:
            continue
        half = (ci[1] - val) if true >= val else (val - ci[0])
        dist = abs(true - val) / half if half > 0 else float("inf")
        out[name] = (bool(ci[0] <= true <= ci[1]), str(p.get("how")), float(dist))
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("cases")
    ap.add_argument("--json")
    a = ap.parse_args()
    warnings.simplefilter("ignore")
    rows = []
    for d in sorted(p for p in Path(a.cases).iterdir() if (p / "truth.json").exists()):
        r = score(d)
        rows.append(r)
        worst = max((abs(e) for e, det in r["errors"].values() if det), default=0.0)
        und = [k for k, (e, det) in r["errors"].items() if not det]
        print(f"{r['case']} {r['trajectory']:6s} {r['loop']:8s} {r['rate_hz']:6.0f} Hz "
              f"{r['mass_true']:6.1f} kg  true {100 * r['true']:6.3f} %  fitted "
              f"{100 * r['fitted']:6.3f} %  x{r['ratio']:5.2f}  worst determined "
              f"{100 * worst:5.2f} %  {r['seconds']:.2f} s  not determined: {','.join(und)}",
              flush=True)
    ratios = np.array([r["ratio"] for r in rows])
    print(f"ratio fitted/true: median {np.median(ratios):.3f}, worst {ratios.max():.3f}")
    bad = [(r["case"], k, e) for r in rows for k, (e, det) in r["errors"].items()
           if det and abs(e) > 0.05]
    print(f"determined parameters off by more than 5 %: {len(bad)}")
    for b in bad:
        print(f"  {b[0]} {b[1]} {100 * b[2]:+.1f} %")
    _coverage(rows)
    if a.json:
        Path(a.json).write_text(json.dumps(rows, indent=1))


def _coverage(rows: list[dict]) -> None:
    """How many 95 % intervals hold the truth, by how they were had and by parameter."""
    cov = [(name, ok, how, d) for r in rows for name, (ok, how, d) in r["covered"].items()]
    for how in sorted({c[2] for c in cov}):
        sub = [c for c in cov if c[2] == how]
        dist = np.array([c[3] for c in sub])
        print(f"95 % intervals ({how}) holding the truth: {sum(c[1] for c in sub)} of "
              f"{len(sub)}; the truth's distance in half-widths: median "
              f"{np.median(dist):.2f}, 90th percentile {np.percentile(dist, 90):.2f}, "
              f"95th {np.percentile(dist, 95):.2f}")
    for name in sorted({c[0] for c in cov}):
        sub = [c for c in cov if c[0] == name]
        print(f"  {name}: {sum(c[1] for c in sub)} of {len(sub)}")


if __name__ == "__main__":
    main()
