"""Outputs: regular files whole or not at all, devices, FIFOs and ``-`` written through
(never replaced), arguments in either order said clearly."""

from __future__ import annotations

import json
import os
import stat
import subprocess
import sys
import threading

import lugre
import numpy as np
import pytest
from lugre._atomic import atomic_write


def _record(tmp_path):
    t = np.arange(0, 6, 1e-3)
    xr = 0.02 * np.sin(2 * np.pi * 0.5 * t)
    r = lugre.simulate(lugre.Model.paper(), t, x_ref=xr)
    rec = lugre.Recording.from_simulation(r, x_ref=xr, quantum=1e-6, current_noise=0.01, seed=3)
    path = tmp_path / "rec.csv"
    lugre.write_recording(rec, path)
    lugre.save_model(lugre.Model.paper(), tmp_path / "m.json")
    return path


def _evaluate(tmp_path, out):
    rec = _record(tmp_path)
    return subprocess.run([sys.executable, "-m", "lugre", "evaluate", str(rec), "--model",
                           str(tmp_path / "m.json"), "--json", str(out)],
                          capture_output=True, text=True, check=False)


def test_a_device_is_written_through_not_replaced(tmp_path):
    """``--json /dev/null`` throws the output away and leaves the device a device."""
    r = _evaluate(tmp_path, "/dev/null")
    assert r.returncode == 0, r.stderr
    assert stat.S_ISCHR(os.stat("/dev/null").st_mode)


def test_a_fifo_is_written_through(tmp_path):
    fifo = tmp_path / "out.fifo"
    os.mkfifo(fifo)
    got = []

    def read():
        with open(fifo, "rb") as fh:
            got.append(fh.read())

    th = threading.Thread(target=read)
    th.start()
    r = _evaluate(tmp_path, fifo)
    th.join(timeout=60)
    assert r.returncode == 0, r.stderr
    assert stat.S_ISFIFO(os.stat(fifo).st_mode)
    assert json.loads(got[0])["rms_force"] > 0


def test_dash_writes_the_output_alone_to_stdout(tmp_path):
    r = _evaluate(tmp_path, "-")
    assert r.returncode == 0, r.stderr
    doc = json.loads(r.stdout)  # nothing but the JSON on standard output
    assert doc["nrmse_force"] > 0
    assert "rms force residual" in r.stderr


def test_atomic_write_keeps_a_regular_file_whole(tmp_path):
    p = tmp_path / "a.txt"
    atomic_write(p, b"one")
    atomic_write(p, b"two")
    assert p.read_bytes() == b"two"
    assert [q.name for q in tmp_path.iterdir()] == ["a.txt"]


def test_save_model_with_its_arguments_swapped_says_so(tmp_path):
    with pytest.raises(ValueError, match=r"save_model\(model, path\)"):
        lugre.save_model(str(tmp_path / "m.json"), lugre.Model.paper())


def test_write_recording_takes_either_order_and_a_simulation(tmp_path):
    t = np.arange(0, 0.5, 1e-3)
    r = lugre.simulate(lugre.Model.paper(), t, x_ref=0.01 * t)
    rec = lugre.Recording.from_simulation(r)
    lugre.write_recording(rec, tmp_path / "a.csv")
    lugre.write_recording(tmp_path / "b.csv", rec)
    lugre.write_recording(r, tmp_path / "c.csv")
    a, b, c = (lugre.read_recording(tmp_path / f"{k}.csv") for k in "abc")
    assert np.array_equal(a.x, b.x) and np.array_equal(a.i, c.i)
    with pytest.raises(ValueError, match="write_recording"):
        lugre.write_recording(rec, 3.0)


def test_from_simulation_adds_the_drive_s_imperfections():
    t = np.arange(0, 0.5, 1e-3)
    r = lugre.simulate(lugre.Model.paper(), t, x_ref=0.01 * t)
    rec = lugre.Recording.from_simulation(r, quantum=1e-5, current_noise=0.1, seed=1)
    assert np.allclose(rec.x / 1e-5, np.round(rec.x / 1e-5))
    assert 0.05 < np.std(rec.i - r.i) < 0.2
    with pytest.raises(ValueError, match="quantum"):
        lugre.Recording.from_simulation(r, quantum=-1.0)


def test_diagnose_draws_figures_only_when_asked(tmp_path):
    """Without --plots no figure is drawn (they took longer than the diagnosis); with it
    the figures land in the directory given."""
    rec = _record(tmp_path)
    base = [sys.executable, "-m", "lugre", "diagnose", str(rec), "--model",
            str(tmp_path / "m.json")]
    r = subprocess.run(base + ["--json", str(tmp_path / "a.json")], capture_output=True,
                       text=True, check=False)
    assert r.returncode == 0, r.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.json", "m.json", "rec.csv"]
    assert "plots written" not in r.stdout
    r = subprocess.run(base + ["--json", str(tmp_path / "b.json"), "--plots",
                               str(tmp_path / "figs")], capture_output=True, text=True,
                       check=False)
    assert r.returncode == 0, r.stderr
    assert {p.name for p in (tmp_path / "figs").iterdir()} == {
        "residual_time.png", "residual_position.png", "residual_velocity.png",
        "residual_spectrum.png", "overlay.png"}
