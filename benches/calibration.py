"""The calibration bench of issue 27: false findings on clean records and detection
curves against the limits the tool itself reports, on records of the independent
plant of ``calibration_cases.py``:

    python benches/calibration.py OUT_DIR [--seed 27000] [--clean 500] [--sweep 20]
        [--jobs 1] [--batch 12] [--sweep-max-duration 20]

(a) ``--clean`` records drawn from seeds ``seed, seed+1, ...`` (no effect) are diagnosed
against their believed model (the truth's base off by 0.5-2 %, no effects). A record
with any named finding counts as a false finding; its exact Clopper-Pearson 95 %
interval is given. A ``mass`` finding within half of the believed model's own mass
error (``true - believed``) is reported apart: it names a real error of the model
handed in, not an effect the record does not hold.

The rate the tool's own p-values predict: every trial of the search (each candidate at
the best point of its grid, at each step: the report's ``trials``) is a one-sided
t-test of the held-out block gains at level ``alpha`` = 1e-3 (``scoring.accept``), and
a finding needs one to pass (besides a gain over 10 and the checks after it). If the
nominal p-values were what they claim, a clean record would name something with a
probability of at most ``alpha`` times the number of trials run on it (the union
bound); the predicted rate is that bound averaged over the records,
``mean_r min(1, alpha * trials_r)``. Also given: the share of records where any trial's
nominal p is under ``alpha`` at all (whatever its gain). The "confined but overwhelming"
route (gain over 20x the threshold, no p-value) has no nominal rate; findings taken
through it are counted apart.

(b) ``--sweep`` of the clean records that the tool cleared (nothing named), at most
``--sweep-max-duration`` s long, half rotary and half linear where there are, are
regenerated (same seed: the same axis, trajectory and noise) with one effect at 0.5x,
1x and 2x the size under which that record's report says the effect would not be seen
(``could_not_reveal``); an effect whose limit is infinite ("any size", not determined)
or whose multiple leaves the effect's range (a load fraction over 0.9) is skipped and
counted. Per effect and multiple: the share of records where the effect is named.

Writes ``OUT_DIR/calibration.json`` (every record's result, updated as they come in)
and ``OUT_DIR/calibration.md`` (the tables). Progress on stderr.
"""

from __future__ import annotations

import argparse
import json
import math
import re
import sys
import time
import traceback
from collections import Counter, defaultdict
from multiprocessing import Pool
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import calibration_cases as C

ALPHA = 1e-3  # the diagnosis's default per-test level (diagnose(alpha=1e-3))
MULTIPLES = (0.5, 1.0, 2.0)
#: The report's ``could_not_reveal`` entry each swept effect is sized by.
LIMIT_OF = {"delay": "delay/current_lag", "current_lag": "delay/current_lag"}
SWEPT = ("offset", "spring", "mass", "cogging", "position_friction", "drift", "delay",
         "current_lag", "drag", "deadband", "stribeck_shape", "resonance", "gravity",
         "load_friction", "force_ripple", "current_limit")
TIMING = {"delay", "current_lag"}


# ------------------------------------------------------------------------ diagnosing

def _diagnose(case: dict[str, Any], rec: dict[str, np.ndarray], hold: dict[str, np.ndarray]
              ) -> dict[str, Any]:
    """Diagnose one record against its believed model; the parts of the report the
    bench reads."""
    from lugre.diagnosis import diagnose
    from lugre.io import Recording
    from lugre.model import Model

    kind = case["truth"]["axis"].get("kind", "linear")
    t0 = time.time()
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        d = diagnose(Recording(**rec, meta={"axis_kind": kind}), Model(case["believed"]),
                     holdout=Recording(**hold, meta={"axis_kind": kind})).to_dict()
    trials = d.get("trials") or []
    ps = [float(tr["p"]) for tr in trials if tr.get("p") is not None
          and math.isfinite(float(tr["p"]))]
    return {
        "findings": [{"effect": f["effect"], "parameters": f["parameters"],
                      "evidence": f.get("evidence", "")} for f in d["findings"]],
        "minor": [m.get("effect") for m in d.get("minor") or []],
        "trials": len(ps),
        "min_p": min(ps) if ps else None,
        "trials_p_under_alpha": sum(p < ALPHA for p in ps),
        "accepted_overwhelming": sum(1 for tr in trials if tr.get("accepted")
                                     and not tr.get("p", 1.0) < ALPHA),
        "could_not_reveal": [{k: c.get(k) for k in ("effect", "smallest", "unit", "text", "range",
                                                         "by_pitch")}
                             for c in d.get("could_not_reveal") or []],
        "nrmse_before": d["fit"]["before"]["nrmse_force"],
        "nrmse_after": d["fit"]["after"]["nrmse_force"],
        "seconds": round(time.time() - t0, 2),
        # the first step's trials (each candidate against the base) and the motor
        # force's rms, for benches/sensitivity.py
        "first_step": [{k: tr.get(k) for k in ("effect", "gain", "p", "positive", "blocks",
                                               "ratio", "contrib", "accepted")}
                       for tr in trials if tr.get("step") == 1],
        "force_rms": _force_rms(case, rec),
    }


def _force_rms(case: dict[str, Any], rec: dict[str, np.ndarray]) -> float:
    """The motor force's rms [N] (N m on a rotary axis), from the recorded current."""
    ax = case["believed"]["axis"]
    kf = float(ax.get("force_constant", ax.get("torque_constant", 1.0)))
    return float(kf * np.sqrt(np.mean(np.asarray(rec["i"]) ** 2)))


def _mass_error(case: dict[str, Any]) -> float:
    g = lambda m: m["axis"].get("mass", m["axis"].get("inertia"))
    return float(g(case["truth"]) - g(case["believed"]))


def clean_batch(seeds: list[int], max_duration: float, min_duration: float = 3.0
                ) -> list[dict[str, Any]]:
    """Simulate a batch of clean cases as lanes of one run, diagnose each."""
    cases = [C.draw_case(s, max_duration=max_duration, min_duration=min_duration)
             for s in seeds]
    out = []
    try:
        recs = C.records([(c, []) for c in cases])
    except Exception as e:  # noqa: BLE001  (a batch that fails is recorded, the run goes on)
        return [{"phase": "clean", "seed": c["seed"], "family": c["family"],
                 "error": f"simulation: {e!r}"} for c in cases]
    for c, (r, h) in zip(cases, recs):
        row = {"phase": "clean", "seed": c["seed"], "family": c["family"],
               "mass_error": _mass_error(c), "duration": c["setup"]["duration"],
               "x_range": [float(np.min(r["x"])), float(np.mean(r["x"])),
                           float(np.max(r["x"]))]}
        try:
            row.update(_diagnose(c, r, h))
        except Exception as e:  # noqa: BLE001
            row["error"] = f"{type(e).__name__}: {e}"
            row["traceback"] = traceback.format_exc(limit=3)
        out.append(row)
    return out


# ------------------------------------------------------------------------ sizing

_LEN = {"mm": 1e-3, "m": 1.0, "um": 1e-6, "µm": 1e-6, "rad": 1.0, "mrad": 1e-3,
        "deg": math.pi / 180, "°": math.pi / 180}


def _pitch_range(text: str) -> tuple[float, float] | None:
    m = re.search(r"at pitches ([0-9.eE+-]+) to ([0-9.eE+-]+) (\S+)", text)
    if not m or m.group(3).rstrip(",") not in _LEN:
        return None
    f = _LEN[m.group(3).rstrip(",")]
    return float(m.group(1)) * f, float(m.group(2)) * f


def _freq_range(text: str) -> tuple[float, float] | None:
    m = re.search(r"at ([0-9.eE+-]+) to ([0-9.eE+-]+) Hz", text)
    return (float(m.group(1)), float(m.group(2))) if m else None


def _at_pitch(by_pitch: dict[str, Any], pitch: float) -> float | None:
    """The reported limit at ``pitch``, interpolated in log pitch and log size."""
    p, b = by_pitch.get("pitch") or [], by_pitch.get("smallest") or []
    pts = sorted((math.log(pp), math.log(bb)) for pp, bb in zip(p, b) if bb and bb > 0)
    if len(pts) < len(p) or len(pts) < 2:
        return None
    xs, ys = zip(*pts)
    return float(math.exp(np.interp(math.log(pitch), xs, ys)))


def _periodic(name: str, mult: float, s: float, lim: dict[str, Any],
              limits: dict[str, dict[str, Any]], ph: float, rng: np.random.Generator
              ) -> tuple[dict[str, Any] | None, str]:
    """A cogging or a ripple at a pitch drawn in the middle half (in log) of the range
    searched, sized at ``mult`` times the limit the report gives at that pitch (the
    largest over the range on reports without limits per pitch)."""
    bp = lim.get("by_pitch")
    if bp and bp.get("pitch"):
        pr: tuple[float, float] | None = (min(bp["pitch"]), max(bp["pitch"]))
    else:
        pr = _pitch_range(limits.get("cogging", {}).get("text") or "")
    if pr is None:
        return None, "no pitch range in the report"
    u = float(rng.uniform(0.25, 0.75))
    pitch = float(np.exp(np.log(pr[0]) + u * (np.log(pr[1]) - np.log(pr[0]))))
    if bp:
        at = _at_pitch(bp, pitch)
        if at is None:
            return None, "limit not finite at the drawn pitch"
        s = mult * at
    return {"effect": name, "amplitude": s, "pitch": pitch, "phase": ph}, ""


def sized(name: str, mult: float, limits: dict[str, dict[str, Any]], case: dict[str, Any],
          x: np.ndarray, rng: np.random.Generator) -> tuple[dict[str, Any] | None, str]:
    """The effect ``name`` at ``mult`` times the record's reported limit, or None and
    why it is skipped (``x``: the clean record's least, mean and largest position)."""
    lim = limits.get(LIMIT_OF.get(name, name))
    if lim is None:
        return None, "no limit reported"
    b = lim.get("smallest")
    if b is None or not math.isfinite(float(b)) or b <= 0:
        return None, "limit not finite (any size hidden, or not determined)"
    s = mult * float(b)
    lo, hi = float(np.min(x)), float(np.max(x))
    span, mid, mean = hi - lo, 0.5 * (lo + hi), float(x[1])
    ph = float(rng.uniform(-np.pi, np.pi))
    if name == "offset":
        return {"effect": "offset", "force": s * float(rng.choice([-1.0, 1.0]))}, ""
    if name == "spring":
        return {"effect": "spring", "stiffness": s, "x0": mid}, ""
    if name == "mass":
        return {"effect": "mass", "delta": s}, ""
    if name in ("cogging", "force_ripple"):
        return _periodic(name, mult, s, lim, limits, ph, rng)
    if name == "position_friction":
        c = mean
        return {"effect": "position_friction",
                "positions": [c - 0.12 * span, c - 0.08 * span, c + 0.08 * span,
                              c + 0.12 * span], "scale": [1.0, 1.0 + s, 1.0 + s, 1.0]}, ""
    if name == "drift":
        T = case["setup"]["duration"]
        tau = 2.0 * T
        return {"effect": "drift", "gain": s / (1 - math.exp(-T / tau)), "time_constant": tau}, ""
    if name == "delay":
        return {"effect": "delay", "seconds": s}, ""
    if name == "current_lag":
        return {"effect": "current_lag", "bandwidth": 1.0 / (2 * math.pi * s)}, ""
    if name in ("drag", "deadband", "load_friction"):
        key = {"drag": "coefficient", "deadband": "current", "load_friction": "coefficient"}
        return {"effect": name, key[name]: s}, ""
    if name == "stribeck_shape":
        # one side at every multiple: below 2 on odd seeds, unless 2x the limit would
        # take the exponent under 0.3
        side = 1.0 if case["seed"] % 2 == 0 or 2.0 - 2.0 * float(b) < 0.3 else -1.0
        rng_ = lim.get("range")
        if rng_:  # the report gives each side's limit: the side's own margin
            lo, hi = rng_
            edge = hi if side > 0 else lo
            if edge is None:
                return None, "limit not finite on this side"
            s = mult * abs(float(edge) - 2.0)
            if side < 0 and 2.0 - s < 0.3:
                return None, "exponent under 0.3"
        return {"effect": "stribeck_shape", "exponent": 2.0 + side * s}, ""
    if name == "resonance":
        fr = _freq_range(lim.get("text") or "")
        if fr is None or "half the mass" in (lim.get("text") or ""):
            return None, "no frequency range where the limit holds"
        if s > 0.9:
            return None, "load fraction over 0.9"
        u = float(rng.uniform(0.25, 0.75))
        f = float(np.exp(np.log(fr[0]) + u * (np.log(fr[1]) - np.log(fr[0]))))
        return {"effect": "resonance", "frequency": f, "damping_ratio": 0.05,
                "load_fraction": s}, ""
    if name == "gravity":
        return {"effect": "gravity", "torque": s, "phase": ph}, ""
    if name == "current_limit":
        return {"effect": "current_limit", "current": s}, ""
    return None, "not swept"


def named(effect: str, findings: list[dict[str, Any]]) -> bool:
    """Whether the report names the effect (either timing form for a timing effect)."""
    names = {f["effect"] for f in findings}
    if effect in TIMING:
        return bool(names & TIMING)
    return effect in names or (effect == "mass" and "inertia" in names)


def sweep_case(seed: int, base: dict[str, Any], max_duration: float,
               min_duration: float = 3.0, effects: tuple[str, ...] = SWEPT
               ) -> list[dict[str, Any]]:
    """One clean record regenerated with each effect (of ``effects``) at each multiple
    of its limit."""
    case = C.draw_case(seed, max_duration=max_duration, min_duration=min_duration)
    limits = {c["effect"]: c for c in base["could_not_reveal"]}
    x = np.array(base["x_range"])  # the clean record's positions: min, mean, max
    rotary = case["truth"]["axis"].get("kind") == "rotary"
    jobs, rows = [], []
    for name in (n for n in SWEPT if n in effects):
        if name == "gravity" and not rotary:
            continue
        for mult in MULTIPLES:
            # the same draws (pitch, phase, sign, frequency) at every multiple
            rng = np.random.default_rng([2727, seed, SWEPT.index(name)])
            eff, why = sized(name, mult, limits, case, x, rng)
            row = {"phase": "sweep", "seed": seed, "family": case["family"], "effect": name,
                   "multiple": mult}
            if eff is None:
                rows.append({**row, "skipped": why})
                continue
            row["truth"] = eff
            if name == "stribeck_shape":
                row["side"] = "above 2" if eff["exponent"] > 2 else "below 2"
            jobs.append((row, eff))
    try:
        recs = C.records([(case, [eff]) for _, eff in jobs])
    except Exception as e:  # noqa: BLE001
        return rows + [{**row, "error": f"simulation: {e!r}"} for row, _ in jobs]
    for (row, _eff), (r, h) in zip(jobs, recs):
        try:
            res = _diagnose(case, r, h)
            res.pop("could_not_reveal", None)
            row.update(res)
            row["found"] = named(row["effect"], res["findings"])
        except Exception as e:  # noqa: BLE001
            row["error"] = f"{type(e).__name__}: {e}"
        rows.append(row)
    return rows


# ------------------------------------------------------------------------ statistics

def clopper_pearson(k: int, n: int, level: float = 0.95) -> tuple[float, float]:
    from scipy.stats import beta

    a = 1 - level
    lo = 0.0 if k == 0 else float(beta.ppf(a / 2, k, n - k + 1))
    hi = 1.0 if k == n else float(beta.ppf(1 - a / 2, k + 1, n - k))
    return lo, hi


def is_mass_correction(row: dict[str, Any], f: dict[str, Any]) -> bool:
    """A mass finding within half of the believed model's own mass error."""
    if f["effect"] not in ("mass", "inertia"):
        return False
    err = row.get("mass_error", 0.0)
    return abs(float(f["parameters"].get("delta", 0.0)) - err) <= 0.5 * abs(err)


def summarise(rows: list[dict[str, Any]], args: dict[str, Any]) -> tuple[dict[str, Any], str]:
    clean = [r for r in rows if r["phase"] == "clean"]
    ok = [r for r in clean if "error" not in r]
    n = len(ok)
    ff = [r for r in ok if r["findings"]]
    ff_strict = [r for r in ok if any(not is_mass_correction(r, f) for f in r["findings"])]
    k, ks = len(ff), len(ff_strict)
    pred = float(np.mean([min(1.0, ALPHA * r["trials"]) for r in ok])) if ok else float("nan")
    any_p = sum(1 for r in ok if r["trials_p_under_alpha"] > 0)
    over = sum(1 for r in ok if r.get("accepted_overwhelming", 0) > 0)
    by_effect = Counter(f["effect"] for r in ff for f in r["findings"])
    fams: dict[str, list[int]] = defaultdict(lambda: [0, 0, 0])
    for r in ok:
        parts = r["family"].split("/")
        for key in (*parts[:4], f"record at {parts[4]}"):
            fams[key][0] += 1
            fams[key][1] += bool(r["findings"])
            fams[key][2] += any(not is_mass_correction(r, f) for f in r["findings"])
    S: dict[str, Any] = {
        "args": args,
        "clean": {"records": len(clean), "diagnosed": n, "errors": len(clean) - n,
                  "with_finding": k, "rate": k / n if n else None,
                  "ci95": clopper_pearson(k, n) if n else None,
                  "with_finding_besides_mass_correction": ks,
                  "rate_besides_mass_correction": ks / n if n else None,
                  "ci95_besides_mass_correction": clopper_pearson(ks, n) if n else None,
                  "predicted_rate_union_bound": pred,
                  "records_any_trial_p_under_alpha": any_p,
                  "records_accepted_overwhelming": over,
                  "mean_trials": float(np.mean([r["trials"] for r in ok])) if ok else None,
                  "named_effects": dict(by_effect),
                  "by_family": {f: {"records": v[0], "with_finding": v[1],
                                    "besides_mass_correction": v[2]}
                                for f, v in sorted(fams.items())},
                  "false_findings": [{"seed": r["seed"], "family": r["family"],
                                      "effects": [f["effect"] for f in r["findings"]],
                                      "mass_correction": [is_mass_correction(r, f)
                                                          for f in r["findings"]]}
                                     for r in ff]}}
    sw = [r for r in rows if r["phase"] == "sweep"]
    det: dict[str, dict[str, Any]] = {}
    for name in SWEPT:
        d = {}
        for mult in MULTIPLES:
            rs = [r for r in sw if r["effect"] == name and r["multiple"] == mult]
            run = [r for r in rs if "found" in r]
            d[str(mult)] = {"found": sum(r["found"] for r in run), "run": len(run),
                            "any_finding": sum(bool(r["findings"]) for r in run),
                            "skipped": sum(1 for r in rs if "skipped" in r),
                            "errors": sum(1 for r in rs if "error" in r)}
        if name == "stribeck_shape":
            for side in ("above 2", "below 2"):
                for mult in MULTIPLES:
                    run = [r for r in sw if r["effect"] == name and r["multiple"] == mult
                           and r.get("side") == side and "found" in r]
                    d[f"{mult} {side}"] = {"found": sum(r["found"] for r in run),
                                           "run": len(run),
                                           "any_finding": sum(bool(r["findings"]) for r in run)}
        det[name] = d
    S["detection"] = det
    S["sweep_seeds"] = sorted({r["seed"] for r in sw})
    S["sweep_misses_at_2x"] = [{"seed": r["seed"], "family": r["family"],
                                "effect": r["effect"], "named": [f["effect"] for f in
                                                                 r["findings"]]}
                               for r in sw if r.get("multiple") == 2.0 and "found" in r
                               and not r["found"]]
    S["sweep_claims_at_half"] = [{"seed": r["seed"], "family": r["family"],
                                  "effect": r["effect"]}
                                 for r in sw if r.get("multiple") == 0.5 and r.get("found")]
    return S, markdown(S)


def _pc(k: int, n: int) -> str:
    return f"{k}/{n} ({100 * k / n:.0f} %)" if n else "-"


def markdown(S: dict[str, Any]) -> str:
    c = S["clean"]
    a = S["args"]
    lo, hi = c["ci95"] or (float("nan"), float("nan"))
    lo2, hi2 = c["ci95_besides_mass_correction"] or (float("nan"), float("nan"))
    out = [(f"Seeds {a['seed']}..{a['seed'] + a['clean'] - 1} (clean), command: "
           f"`{a['command']}`"), "",
           ("| clean records | diagnosed | errors | with a named finding | rate | 95 % CI "
           "(Clopper-Pearson) |"), "|---|---|---|---|---|---|",
           (f"| {c['records']} | {c['diagnosed']} | {c['errors']} | {c['with_finding']} | "
           f"{100 * (c['rate'] or 0):.2f} % | {100 * lo:.2f}-{100 * hi:.2f} % |"),
           (f"| (besides base mass corrections) | | | "
           f"{c['with_finding_besides_mass_correction']} | "
           f"{100 * (c['rate_besides_mass_correction'] or 0):.2f} % | "
           f"{100 * lo2:.2f}-{100 * hi2:.2f} % |"), "",
           (f"Predicted by the nominal p-values (alpha x trials, union bound): "
           f"{100 * c['predicted_rate_union_bound']:.2f} % (mean {c['mean_trials']:.1f} "
           f"trials a record); records with any trial at nominal p < alpha: "
           f"{c['records_any_trial_p_under_alpha']}; records with a finding accepted on the "
           f"'overwhelming' route (no p-value): {c['records_accepted_overwhelming']}."), "",
           "Named on clean records: " + (", ".join(f"{k} {v}" for k, v in
                                                    sorted(c["named_effects"].items()))
                                         or "nothing"), "",
           "| family | records | with a finding | besides base mass corrections |",
           "|---|---|---|---|"]
    out += [f"| {f} | {v['records']} | {v['with_finding']} | "
            f"{v['besides_mass_correction']} |" for f, v in c["by_family"].items()]
    out += ["", ("Detection against the reported limit (named / run; skipped = limit "
            "infinite or out of range):"), "",
            ("| effect | 0.5x | 1x | 2x | anything named at 0.5x / 1x / 2x | skipped "
            "| errors |"), "|---|---|---|---|---|---|---|"]
    for name, d in S["detection"].items():
        sk = sum(d[str(m)]["skipped"] for m in MULTIPLES)
        er = sum(d[str(m)]["errors"] for m in MULTIPLES)
        out.append(f"| {name} | " + " | ".join(_pc(d[str(m)]["found"], d[str(m)]["run"])
                                               for m in MULTIPLES)
                   + " | " + " / ".join(str(d[str(m)]["any_finding"]) for m in MULTIPLES)
                   + f" | {sk} | {er} |")
        if name == "stribeck_shape":
            for side in ("above 2", "below 2"):
                out.append(f"| stribeck_shape, {side} | " + " | ".join(
                    _pc(d[f'{m} {side}']["found"], d[f'{m} {side}']["run"])
                    for m in MULTIPLES) + " | " + " / ".join(
                    str(d[f'{m} {side}']["any_finding"]) for m in MULTIPLES) + " | | |")
    out += ["", f"Sweep seeds: {S['sweep_seeds']}", ""]
    return "\n".join(out)


# ------------------------------------------------------------------------ main

def _clean_job(args: tuple[list[int], float, float]) -> list[dict[str, Any]]:
    return clean_batch(*args)


def _sweep_job(args: tuple[int, dict[str, Any], float, float, tuple[str, ...]]
               ) -> list[dict[str, Any]]:
    try:
        return sweep_case(*args)
    except Exception as e:  # noqa: BLE001
        return [{"phase": "sweep", "seed": args[0], "effect": None, "multiple": None,
                 "error": f"{type(e).__name__}: {e}"}]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out")
    ap.add_argument("--seed", type=int, default=27000)
    ap.add_argument("--clean", type=int, default=500)
    ap.add_argument("--sweep", type=int, default=20, help="clean records to sweep")
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--batch", type=int, default=12, help="clean cases simulated together")
    ap.add_argument("--max-duration", type=float, default=60.0)
    ap.add_argument("--min-duration", type=float, default=3.0,
                    help="clip the drawn durations from below (long-record runs)")
    ap.add_argument("--sweep-max-duration", type=float, default=20.0)
    ap.add_argument("--effects", default=",".join(SWEPT), metavar="E1,E2",
                    help="effects to sweep (default all)")
    ap.add_argument("--summarise", action="store_true",
                    help="only rewrite the tables from OUT_DIR/calibration.json")
    a = ap.parse_args()
    out = Path(a.out)
    swept = tuple(e for e in a.effects.split(",") if e)
    unknown = sorted(set(swept) - set(SWEPT))
    if unknown:
        sys.exit(f"calibration.py: --effects: unknown {', '.join(unknown)}; use some of "
                 f"{', '.join(SWEPT)}")
    if a.summarise:
        saved = json.loads((out / "calibration.json").read_text())
        S, md = summarise(saved["records"], saved["summary"]["args"])
        (out / "calibration.json").write_text(json.dumps({"summary": S, "records":
                                                          saved["records"]}, indent=1))
        (out / "calibration.md").write_text(md)
        print(md)
        return
    out.mkdir(parents=True, exist_ok=True)
    args = {**vars(a), "command": "python benches/calibration.py " + " ".join(sys.argv[1:])}
    seeds = list(range(a.seed, a.seed + a.clean))
    # cases of similar length run together (a lane runs as long as the batch's longest)
    dur = {s: C.draw_case(s, max_duration=a.max_duration, min_duration=a.min_duration)
           ["setup"]["duration"] for s in seeds}
    order = sorted(seeds, key=lambda s: dur[s])
    batches = [(order[j:j + a.batch], a.max_duration, a.min_duration)
               for j in range(0, len(order), a.batch)]
    rows: list[dict[str, Any]] = []
    t0 = time.time()

    def save() -> None:
        S, md = summarise(rows, args)
        (out / "calibration.json").write_text(json.dumps({"summary": S, "records": rows},
                                                         indent=1, default=str))
        (out / "calibration.md").write_text(md)

    pool = Pool(a.jobs) if a.jobs > 1 else None
    mapper = pool.imap_unordered if pool else map
    for res in mapper(_clean_job, batches):
        rows += res
        k = sum(1 for r in rows if r.get("findings"))
        print(f"[{time.time() - t0:6.0f} s] clean {len(rows)}/{len(seeds)}, {k} with a "
              f"finding, {sum('error' in r for r in rows)} errors", file=sys.stderr,
              flush=True)
        save()
    ok = sorted((r for r in rows if r["phase"] == "clean" and "error" not in r
                 and not r["findings"] and r["duration"] <= a.sweep_max_duration),
                key=lambda r: r["seed"])
    rot = [r for r in ok if r["family"].startswith("rotary")]
    lin = [r for r in ok if r["family"].startswith("linear")]
    half = (a.sweep + 1) // 2
    pick = rot[:half] + lin[:a.sweep - min(half, len(rot))]
    pick = pick + [r for r in ok if r not in pick][:a.sweep - len(pick)]
    jobs = [(r["seed"], r, a.max_duration, a.min_duration, swept) for r in pick]
    for done, res in enumerate(mapper(_sweep_job, jobs), 1):
        rows += res
        print(f"[{time.time() - t0:6.0f} s] sweep {done}/{len(jobs)} (seed {res[0]['seed']})",
              file=sys.stderr, flush=True)
        save()
    if pool:
        pool.close()
        pool.join()
    save()
    print((out / "calibration.md").read_text())


if __name__ == "__main__":
    main()
