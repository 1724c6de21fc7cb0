"""The user's chain on diagnosis cases: each case's ``model.json`` replaced by what
``lugre fit`` makes of its recording (force constant given, mass fitted), so that
``lugre diagnose`` starts from the tool's own fit instead of a model close to the truth:

    python benches/fit_then_diagnose.py CASES_DIR OUT_DIR [--mass]
    python ../shared/tools/score_diagnosis.py OUT_DIR - $(which lugre)

``--mass`` gives the fit the believed model's mass. The recordings, hold-outs and
truths are copied unchanged; the fitted model keeps the believed model's controller.
"""

from __future__ import annotations

import argparse
import json
import shutil
import subprocess
import sys
from pathlib import Path


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("cases")
    ap.add_argument("out")
    ap.add_argument("--mass", action="store_true", help="give the believed mass")
    a = ap.parse_args()
    for d in sorted(p for p in Path(a.cases).iterdir() if (p / "truth.json").exists()):
        o = Path(a.out) / d.name
        o.mkdir(parents=True, exist_ok=True)
        for fn in ("recording.csv", "holdout.csv", "truth.json"):
            shutil.copyfile(d / fn, o / fn)
        believed = json.loads((d / "model.json").read_text())
        axis = believed["axis"]
        rotary = axis.get("kind") == "rotary"  # (joints: inertia, torque constant, rad)
        cmd = [sys.executable, "-m", "lugre", "fit", str(d / "recording.csv"), "-q",
               "--force-constant",
               str(axis["torque_constant" if rotary else "force_constant"]),
               "--json", str(o / "fitted.json")] + (["--x-unit", "rad"] if rotary else [])
        if a.mass:
            cmd += ["--mass", str(axis["inertia" if rotary else "mass"])]
        r = subprocess.run(cmd, capture_output=True, text=True, check=False)
        if r.returncode:
            print(f"{d.name}: fit failed: {r.stderr.strip()}", flush=True)
            continue
        fitted = json.loads((o / "fitted.json").read_text())
        if "controller" in believed:
            fitted["controller"] = believed["controller"]
        (o / "model.json").write_text(json.dumps(fitted, indent=1))
        print(f"{d.name}: fitted", flush=True)


if __name__ == "__main__":
    main()
