"""Time `lugre fit`'s identification on a 20 000-sample record (20 s at 1 kHz, a case of
benches/fit_cases.py's plant), on one core, beside the plain C loop's rate in the same
run (benches/plain_loop.c, as compare.py builds it):

    taskset -c 0 python benches/bench_fit.py [CASE_DIR] [--repeat 5]

Prints the best and median of the fit call (intervals included) and of the whole
command from the shell (`lugre fit ... --json`), and the C loop's steps per second.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
import lugre
from compare import build_c, grid, run_c
from lugre.diagnosis.basefit import identify


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("case", nargs="?", help="a case folder of fit_cases.py (default: one "
                    "is written to a temporary folder, seed 1, case 24)")
    ap.add_argument("--repeat", type=int, default=5)
    a = ap.parse_args()
    tmp = tempfile.TemporaryDirectory()
    case = Path(a.case) if a.case else None
    if case is None:
        subprocess.run([sys.executable, str(Path(__file__).parent / "fit_cases.py"), tmp.name,
                        "--cases", "25"], check=True, capture_output=True)
        case = Path(tmp.name) / "case24"
    rec = lugre.read_recording(case / "recording.csv")
    import json

    kf = json.loads((case / "truth.json").read_text())["axis"]["force_constant"]
    calls = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for _ in range(a.repeat):
            t0 = time.perf_counter()
            identify(rec, force_constant=kf)
            calls.append(time.perf_counter() - t0)
    shell = []
    for _ in range(a.repeat):
        t0 = time.perf_counter()
        subprocess.run(["lugre", "fit", str(case / "recording.csv"), "--force-constant",
                        str(kf), "--json", "/dev/null", "-q"], check=True, capture_output=True)
        shell.append(time.perf_counter() - t0)
    exe = build_c(["-O3"])
    rate = None
    if exe is not None:
        t, xr = grid(2_000_000)
        sec, _ = run_c(exe, t, xr, 2_000_000, 3)
        rate = 2_000_000 / sec
    print(f"record: {len(rec)} samples ({case})")
    print(f"identify (fit, intervals): best {min(calls):.2f} s, median {np.median(calls):.2f} s")
    print(f"lugre fit from the shell: best {min(shell):.2f} s, median {np.median(shell):.2f} s")
    if rate:
        print(f"plain C loop (gcc -O3): {rate / 1e6:.1f} M steps/s")


if __name__ == "__main__":
    main()
