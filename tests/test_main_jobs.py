"""The README's main job (``lugre demo``) and ``lugre paper``, run for real."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest
from lugre.demo import run_demo
from lugre.paper import run_paper


def test_demo_reproduces_the_papers_tracking_figures(tmp_path):
    r = run_demo(tmp_path, verbose=False)
    assert r.stick_stops >= 3  # the slow ramp sticks and slips
    # the seed paper: about 18 cm/s without compensation, below 10 cm/s with it
    assert 0.15 < r.max_speed_error < 0.22
    assert r.max_speed_error_ff < 0.10
    assert len(r.files) == 2
    for f in r.files:
        assert (tmp_path / f).stat().st_size > 10_000


def test_paper_tables(tmp_path):
    res = run_paper(tmp_path, monte_carlo=3, verbose=False)
    t1 = res["table1"]
    # the robust fit beats least squares on the worst parameter
    assert res["worst_static_error"]["igg"] < res["worst_static_error"]["ls"] / 3
    assert abs(t1["positive"]["fs"]["estimate"] / 60.2 - 1) < 0.01
    t2 = res["table2"]
    # sigma0 and sigma1 from the presliding record, within the paper's Table 2 errors
    assert abs(t2["sigma0"]["estimate"] / 1e5 - 1) < 0.021
    assert abs(t2["sigma1"]["estimate"] / 31.62 - 1) < 0.10
    lo, hi = t2["sigma0"]["stick_slip"]["ci95"]
    assert lo <= 1e5 <= hi
    # paper.json holds what run_paper returns, in the shared contract's form
    on_disk = json.loads((tmp_path / "paper.json").read_text())
    assert on_disk == res
    for d in ("positive", "negative"):
        for k in ("fc", "fs", "sigma2", "vs"):
            row = on_disk["table1"][d][k]
            assert {"truth", "paper", "estimate", "ci95"} <= set(row) and len(row["ci95"]) == 2
    for k in ("sigma0", "sigma1"):
        assert {"truth", "paper", "estimate", "ci95"} <= set(on_disk["table2"][k])
    assert res["tracking"]["with"] < 0.10 < res["tracking"]["without"]
    for name in ("paper_static_fit.png", "paper_dynamic_fit.png", "paper_speed_tracking.png"):
        assert (tmp_path / name).stat().st_size > 10_000


def test_cli_without_command_prints_help():
    r = subprocess.run([sys.executable, "-m", "lugre.cli"], capture_output=True, text=True,
                       check=False)
    assert r.returncode == 2 and "fit-static" in r.stdout


@pytest.mark.parametrize("cmd", ["demo", "paper", "fit-static", "fit-dynamic", "fit",
                                 "diagnose", "evaluate", "design-static"])
def test_every_command_has_help(cmd):
    r = subprocess.run([sys.executable, "-m", "lugre.cli", cmd, "--help"], capture_output=True,
                       text=True, check=False)
    assert r.returncode == 0 and "usage: lugre" in r.stdout
