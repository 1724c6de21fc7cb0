"""lugre fleet: a generated fleet (tests/fleetgen.py: 20 axes over 10 nights, three
wearing, one gaining a cogging, one whose cogging grows, a few corrupt files) diagnosed on
the default local Dask cluster and on a 2-worker LocalCluster started here (one of its
workers killed mid-run), the history, the alarms, the page and the command's errors."""

from __future__ import annotations

import datetime as dt
import json
import os
import shutil
import signal
import threading
import time
from pathlib import Path

import fleetgen
import numpy as np
import pytest

pytest.importorskip("dask.distributed")
pytest.importorskip("duckdb")

import duckdb
from lugre import Recording, read_recording, write_recording
from lugre.cli import main
from lugre.fleet import report, run
from lugre.fleet.discover import time_from_name
from lugre.fleet.store import open_store


@pytest.fixture(scope="module")
def fleet(tmp_path_factory):
    return fleetgen.write_fleet(tmp_path_factory.mktemp("fleet") / "plant")


@pytest.fixture(scope="module")
def first(fleet, tmp_path_factory):
    """The fleet run by the command on its default local cluster, and its report."""
    d = tmp_path_factory.mktemp("first")
    db = d / "fleet.duckdb"
    assert main(["fleet", "run", str(fleet.root), "--db", str(db), "-q"]) == 0
    assert main(["fleet", "report", "--db", str(db), "--json", str(d / "ALARMS.json"),
                 "--html", str(d / "fleet.html"), "--parquet", str(d / "tables"), "-q"]) == 0
    return d


def _kill_one_worker_mid_run(client, killed: dict) -> None:
    """Wait until the run is under way, then SIGKILL a worker process that holds tasks."""
    pids = client.run(os.getpid)
    start = time.monotonic()
    while time.monotonic() - start < 300:
        busy = {w: t for w, t in client.processing().items() if t}
        if busy and time.monotonic() - start > 6.0:
            worker = next(iter(busy))
            killed.update(worker=worker, tasks=list(busy[worker]), pid=pids[worker])
            os.kill(pids[worker], signal.SIGKILL)
            return
        time.sleep(0.2)


@pytest.fixture(scope="module")
def second(fleet, tmp_path_factory):
    """The same fleet on a LocalCluster of 2 workers given by --scheduler; one worker is
    killed while it diagnoses."""
    import logging

    from dask.distributed import Client, LocalCluster

    d = tmp_path_factory.mktemp("second")
    db = d / "fleet.duckdb"
    with LocalCluster(n_workers=2, processes=True, threads_per_worker=1,
                      dashboard_address=None, silence_logs=logging.ERROR) as cluster, \
            Client(cluster) as client:
        killed: dict = {}
        killer = threading.Thread(target=_kill_one_worker_mid_run, args=(client, killed))
        killer.start()
        rc = main(["fleet", "run", str(fleet.root), "--db", str(db), "--scheduler",
                   cluster.scheduler_address, "-q"])
        killer.join()
    assert rc == 0
    assert main(["fleet", "report", "--db", str(db), "--json", str(d / "ALARMS.json"),
                 "-q"]) == 0
    return d, killed


def _alarms(d: Path) -> dict:
    return json.loads((d / "ALARMS.json").read_text())


def _rows(db: Path, sql: str) -> list[tuple]:
    con = duckdb.connect(str(db), read_only=True)
    try:
        return con.execute(sql).fetchall()
    finally:
        con.close()


def test_the_fleet_is_large_enough(fleet):
    assert len(fleet.recordings) >= 200 and len(fleet.axes) == 20
    assert len(fleet.corrupt) >= 4


def test_every_changed_axis_ranks_above_every_unchanged_one(first):
    doc = report(first / "fleet.duckdb")
    order = [r["axis"] for r in doc["ranking"]]
    worst_changed = max(order.index(a) for a in fleetgen.CHANGED)
    best_unchanged = min(order.index(a) for a in order if a not in fleetgen.CHANGED)
    assert worst_changed < best_unchanged, order


def test_the_right_alarms_and_none_on_unchanged_axes(first):
    alarms = _alarms(first)["alarms"]
    by_axis: dict[str, set] = {}
    for a in alarms:
        by_axis.setdefault(a["axis"], set()).add((a["kind"], a["effect"]))
        assert set(a) == {"axis", "kind", "effect", "since", "evidence"}
        dt.datetime.fromisoformat(a["since"])
    assert set(by_axis) == set(fleetgen.CHANGED), by_axis
    for axis in fleetgen.WEARING:
        assert ("level", None) in by_axis[axis]
    assert ("new_effect", "cogging") in by_axis[fleetgen.GAINS_EFFECT]
    assert ("growth", "cogging") in by_axis[fleetgen.GROWS]


def test_since_is_when_the_change_set_in(first):
    night = {a["axis"]: (dt.datetime.fromisoformat(a["since"]) - fleetgen.START).days
             for a in _alarms(first)["alarms"]}
    assert night[fleetgen.GAINS_EFFECT] == 6          # the cogging appears on night 6
    assert 5 <= night[fleetgen.GROWS] <= 7            # grows 35 % a night from night 5
    for axis in fleetgen.WEARING:                     # +6 % a night from night 5
        assert 5 <= night[axis] <= 8, (axis, night[axis])


def test_evidence_speaks_the_axis_units(first):
    alarms = {(a["axis"], a["kind"]): a["evidence"] for a in _alarms(first)["alarms"]}
    assert " N m " in alarms[("axis-19", "level")]              # a rotary axis
    linear = alarms[("axis-02", "level")]
    assert " N " in linear and " N m" not in linear and "%" in linear
    assert " mm" in alarms[(fleetgen.GAINS_EFFECT, "new_effect")]  # the pitch


def test_corrupt_files_are_listed_with_their_errors(first):
    errors = _alarms(first)["errors"]
    assert {(e["axis"], e["recording"]) for e in errors} == set(fleet_corrupt(first))
    for e in errors:
        assert e["recording"] in e["error"] and len(e["error"]) > 40


def fleet_corrupt(first: Path) -> set:
    return {(a, r) for a, r in _rows(first / "fleet.duckdb", "SELECT axis, recording FROM "
                                     "recordings WHERE status = 'error'")}


def test_errors_are_the_generated_corrupt_files(first, fleet):
    assert fleet_corrupt(first) == set(fleet.corrupt)


def test_no_half_written_recording(first):
    """Every stored recording has all its rows: its findings and both levels (when ok),
    none when it failed; no row belongs to a recording that is not stored."""
    db = first / "fleet.duckdb"
    rows = _rows(db, """
        SELECT r.axis, r.recording, r.status, r.n_findings,
               (SELECT count(*) FROM findings f WHERE f.axis = r.axis
                AND f.recording = r.recording),
               (SELECT count(*) FROM levels l WHERE l.axis = r.axis
                AND l.recording = r.recording)
        FROM recordings r""")
    assert len(rows) >= 200
    for axis, rec, status, n, found, levels in rows:
        assert found == n, (axis, rec)
        assert levels == (2 if status == "ok" else 0), (axis, rec)
    for table in ("findings", "levels", "limits"):
        orphans = _rows(db, f"SELECT count(*) FROM {table} ANTI JOIN recordings "
                        "USING (axis, recording)")[0][0]
        assert orphans == 0


def test_a_failed_write_leaves_nothing(tmp_path):
    """A write that fails half-way (a parameter JSON cannot hold) is rolled back whole."""
    result = {"axis": "a", "recording": "r.csv", "time": "2024-03-01T02:00:00",
              "status": "ok", "error": None, "levels": [],
              "findings": [{"rank": 0, "effect": "cogging", "parameters": {"x": object()}}]}
    with open_store(tmp_path / "h.duckdb") as store:
        with pytest.raises(TypeError):
            store.put(result)
        assert store.rows("SELECT * FROM recordings") == []
        result["findings"] = []
        store.put(result)
        assert len(store.rows("SELECT * FROM recordings")) == 1


def test_the_same_results_on_a_given_cluster_with_a_worker_killed(first, second):
    d2, killed = second
    assert killed.get("tasks"), "no worker was killed while it held a task"
    assert _alarms(d2) == _alarms(first)
    cols = "axis, recording, time, status, error, n_findings"
    q = f"SELECT {cols}, nrmse_force FROM recordings ORDER BY axis, recording"
    a, b = _rows(first / "fleet.duckdb", q), _rows(d2 / "fleet.duckdb", q)
    assert [r[:-1] for r in a] == [r[:-1] for r in b]
    np.testing.assert_allclose([r[-1] or 0.0 for r in a], [r[-1] or 0.0 for r in b],
                               rtol=1e-9)
    q = "SELECT axis, recording, effect FROM findings ORDER BY axis, recording, rank"
    assert _rows(first / "fleet.duckdb", q) == _rows(d2 / "fleet.duckdb", q)


def test_a_rerun_adds_nothing(first, fleet, capsys):
    db = first / "fleet.duckdb"
    before = _rows(db, "SELECT count(*), max(stored) FROM recordings")
    assert main(["fleet", "run", str(fleet.root), "--db", str(db)]) == 0
    assert "nothing to diagnose" in capsys.readouterr().out
    assert _rows(db, "SELECT count(*), max(stored) FROM recordings") == before


def test_an_interrupted_run_resumes_without_repeating(fleet, tmp_path):
    root = tmp_path / "plant"
    shutil.copytree(fleet.root / "axis-11", root / "axis-11")
    db = tmp_path / "h.duckdb"
    seen = []

    def stop_after_three(result):
        seen.append(result["recording"])
        if len(seen) == 3:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        run(root, db, workers=2, on_result=stop_after_three)
    assert sorted(r[0] for r in _rows(db, "SELECT recording FROM recordings")) == sorted(seen)
    again = run(root, db, workers=2)
    assert again.skipped == 3 and again.stored == fleetgen.NIGHTS - 3
    names = [r[0] for r in _rows(db, "SELECT recording FROM recordings")]
    assert len(names) == len(set(names)) == fleetgen.NIGHTS


def test_parquet_export_has_every_table(first):
    import pyarrow.parquet as pq

    tables = {p.stem: pq.read_table(p) for p in (first / "tables").glob("*.parquet")}
    assert set(tables) == {"axes", "recordings", "findings", "levels", "limits"}
    n = _rows(first / "fleet.duckdb", "SELECT count(*) FROM recordings")[0][0]
    assert tables["recordings"].num_rows == n
    params = tables["findings"].column("parameters").to_pylist()
    assert params and all(isinstance(json.loads(p), dict) for p in params)


def test_fleet_page_renders_and_fetches_nothing(first, tmp_path):
    from htmlcheck import external_references
    from test_browser import CHROMIUM, not_blank, render

    page = first / "fleet.html"
    text = page.read_text()
    assert external_references(text) == []
    for axis in fleetgen.CHANGED:
        assert f"id=\"axis-{axis}\"" in text
    assert text.count("data:image/png;base64,") >= 20
    if CHROMIUM is None:
        pytest.skip("chromium is not installed (apt-get install chromium)")
    for width in (1000, 390):
        pixels, urls = render(page, tmp_path, width=width)
        assert not_blank(pixels) and urls == []


# --------------------------------------------------------------------------------------
# Recordings in Parquet and HDF5, and their time
# --------------------------------------------------------------------------------------


@pytest.mark.parametrize("suffix", [".parquet", ".h5"])
def test_columnar_recordings_round_trip(tmp_path, suffix):
    t = np.arange(100) * 1e-3
    rec = Recording(t=t, x=np.sin(t), i=np.cos(t), x_ref=np.sin(t),
                    meta={"time": "2024-03-01T02:00:00Z", "axis": "x1"})
    write_recording(rec, tmp_path / f"r{suffix}")
    back = read_recording(tmp_path / f"r{suffix}")
    for c in ("t", "x", "i", "x_ref"):
        np.testing.assert_array_equal(getattr(back, c), getattr(rec, c))
    assert back.meta == rec.meta


def test_a_missing_optional_package_is_named(tmp_path, monkeypatch):
    import sys

    from lugre import FileFormatError

    (tmp_path / "r.h5").write_bytes(b"x")
    monkeypatch.setitem(sys.modules, "h5py", None)
    with pytest.raises(FileFormatError, match=r"r\.h5.*pip install h5py"):
        read_recording(tmp_path / "r.h5")


def test_recording_time_from_the_name():
    assert time_from_name("2024-03-01T0215.csv") == dt.datetime(2024, 3, 1, 2, 15)
    assert time_from_name("x_2024-03-01_021530.h5") == dt.datetime(2024, 3, 1, 2, 15, 30)
    assert time_from_name("2024-03-01.npz") == dt.datetime(2024, 3, 1)
    assert time_from_name("night-07.csv") is None


def test_the_time_line_comes_before_the_name(tmp_path):
    from lugre.fleet.task import diagnose_file

    r = diagnose_file("a", str(tmp_path / "2024-01-01.csv"), {}, "")
    assert r["status"] == "error" and r["time"] == "2024-01-01T00:00:00"
    (tmp_path / "2024-01-01.csv").write_text("# time: 2024-05-05T10:00:00+02:00\nt,x,i\n")
    r = diagnose_file("a", str(tmp_path / "2024-01-01.csv"), {}, "")
    assert r["status"] == "error"  # the model {} is refused, after the time was read


# --------------------------------------------------------------------------------------
# The command's errors
# --------------------------------------------------------------------------------------


def _err(argv, capsys) -> tuple[int, str]:
    rc = main(argv)
    return rc, capsys.readouterr().err


def test_missing_dir_is_named(tmp_path, capsys):
    rc, err = _err(["fleet", "run", str(tmp_path / "nowhere"), "--db",
                    str(tmp_path / "f.duckdb")], capsys)
    assert rc == 1 and "nowhere does not exist" in err and "Traceback" not in err


def test_axis_without_model_is_named(tmp_path, capsys):
    (tmp_path / "plant" / "ax1").mkdir(parents=True)
    (tmp_path / "plant" / "ax1" / "2024-03-01.csv").write_text("t,x,i\n0,0,0\n")
    rc, err = _err(["fleet", "run", str(tmp_path / "plant"), "--db",
                    str(tmp_path / "f.duckdb")], capsys)
    assert rc == 1 and "ax1: no model.json" in err
    assert not (tmp_path / "f.duckdb").exists()


def test_unwritable_outputs_are_refused(tmp_path, capsys, first):
    db = str(first / "fleet.duckdb")
    rc, err = _err(["fleet", "run", str(tmp_path), "--db", str(tmp_path / "no" / "f.duckdb")],
                   capsys)
    assert rc == 2 and "does not exist" in err
    rc, err = _err(["fleet", "report", "--db", db, "--html", str(tmp_path / "no" / "f.html")],
                   capsys)
    assert rc == 2 and "--html" in err
    rc, err = _err(["fleet", "report", "--db", db, "--parquet", str(tmp_path / "a" / "b")],
                   capsys)
    assert rc == 2 and "--parquet" in err
    rc, err = _err(["fleet", "report", "--db", db, "--json", db], capsys)
    assert rc == 2 and "never overwritten" in err


def test_report_on_a_missing_or_foreign_history(tmp_path, capsys):
    rc, err = _err(["fleet", "report", "--db", str(tmp_path / "none.duckdb")], capsys)
    assert rc == 1 and "lugre fleet run" in err
    (tmp_path / "x.duckdb").write_text("t,x,i\n")
    rc, err = _err(["fleet", "report", "--db", str(tmp_path / "x.duckdb")], capsys)
    assert rc == 1 and "x.duckdb" in err and "Traceback" not in err
