"""A clean calibration record diagnosed against its believed and its exact true model,
to tell a false finding of the tool from the believed base's own error:

    python benches/calibration_truth.py SEED [SEED ...] [--max-duration 15]

For each model: the findings, and the trials accepted with their route and block
p-value (``scoring.accept``: "consistent over blocks" or "confined but overwhelming").
"""

from __future__ import annotations

import argparse
import sys
import warnings
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import calibration_cases as C
from lugre.diagnosis import diagnose
from lugre.io import Recording
from lugre.model import Model


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("seeds", type=int, nargs="+")
    ap.add_argument("--max-duration", type=float, default=15.0)
    a = ap.parse_args()
    cases = [C.draw_case(s, max_duration=a.max_duration) for s in a.seeds]
    for c, (r, h) in zip(cases, C.records([(c, []) for c in cases])):
        kind = c["truth"]["axis"].get("kind", "linear")
        for label in ("believed", "truth"):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                d = diagnose(Recording(**r, meta={"axis_kind": kind}), Model(c[label]),
                             holdout=Recording(**h, meta={"axis_kind": kind})).to_dict()
            named = [(f["effect"], {k: round(v, 6) if isinstance(v, float) else v
                                    for k, v in f["parameters"].items()})
                     for f in d["findings"]]
            print(f"{c['seed']} {c['family']} against the {label} model: {named}")
            for t in d["trials"]:
                if t.get("accepted"):
                    print(f"    accepted {t['effect']}: gain {t['gain']:.4g}, gains in "
                          f"{t['positive']} of 10 blocks, p = {t['p']:.3g}, {t['why']}")


if __name__ == "__main__":
    main()
