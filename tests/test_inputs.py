"""Bad inputs, tried as a new user would: one line naming the file, row, column or option
and the fix; exit 2 for usage, 1 for data; no traceback; nothing written on refusal."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import lugre
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from lugre.checks import require_plausible, resample_uniform
from lugre.diagnosis.synth import concealed
from lugre.exceptions import DataError, FileFormatError, InputError, LugreError
from lugre.io import read_points, read_recording, write_recording

LUGRE = [sys.executable, "-m", "lugre"]


def run(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess[str]:
    return subprocess.run([*LUGRE, *map(str, args)], capture_output=True, text=True,
                          check=False, cwd=cwd)


def one_line_error(r: subprocess.CompletedProcess[str]) -> str:
    """The error line; fails when there is a traceback or more than one line."""
    assert "Traceback" not in r.stderr, r.stderr
    lines = [ln for ln in r.stderr.splitlines() if ln.strip() and not ln.startswith("warning:")
             and not ln.startswith("note:")]
    assert len(lines) == 1, r.stderr
    return lines[0]


@pytest.fixture(scope="module")
def case(tmp_path_factory):
    """A short recording with a concealed cogging, its model, in a directory of its own."""
    d = tmp_path_factory.mktemp("case")
    rec, believed, _ = concealed("cogging", duration=4.0)
    write_recording(d / "rec.csv", rec)
    lugre.save_model(believed, d / "model.json")
    return d, rec, believed


def snapshot(d: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in d.iterdir() if p.is_file()}


def points_file(d: Path) -> Path:
    v = np.concatenate([np.geomspace(1e-3, 0.3, 12), -np.geomspace(1e-3, 0.3, 12)])
    F = np.sign(v) * (28 + 32 * np.exp(-(v / 0.01) ** 2) + 330 * np.abs(v))
    p = d / "pts.csv"
    p.write_text("v,F\n" + "\n".join(f"{a:.9g},{b:.9g}" for a, b in zip(v, F)) + "\n")
    return p


# ------------------------------------------------------------------- outputs and inputs


def test_fit_static_plot_onto_the_input_is_refused(tmp_path):
    pts = points_file(tmp_path)
    before = pts.read_bytes()
    r = run("fit-static", pts, "--json", tmp_path / "m.json", "--plot", pts)
    line = one_line_error(r)
    assert r.returncode == 2 and "--plot" in line and "input" in line
    assert pts.read_bytes() == before
    assert not (tmp_path / "m.json").exists()


def test_a_figure_never_overwrites_an_input(case, tmp_path):
    """A model named like one of the figures, in the --plots directory: refused before
    anything is written, the model untouched."""
    d, _, believed = case
    model = tmp_path / "overlay.png"
    lugre.save_model(believed, model)
    before = model.read_bytes()
    r = run("diagnose", d / "rec.csv", "--model", model, "--json", tmp_path / "r.json",
            "--plots", tmp_path)
    line = one_line_error(r)
    assert r.returncode == 2 and "--plots" in line and "overlay.png" in line
    assert model.read_bytes() == before
    assert not (tmp_path / "r.json").exists()


def test_plots_onto_an_existing_file_is_refused_before_anything_is_written(case, tmp_path):
    d, _, _ = case
    (tmp_path / "figs").write_text("not a directory")
    r = run("diagnose", d / "rec.csv", "--model", d / "model.json", "--json",
            tmp_path / "r.json", "--plots", tmp_path / "figs")
    line = one_line_error(r)
    assert r.returncode == 2 and "--plots" in line and "not a directory" in line
    assert not (tmp_path / "r.json").exists()


def test_out_model_equal_to_model_names_out_model(case):
    d, _, _ = case
    before = snapshot(d)
    r = run("diagnose", d / "rec.csv", "--model", d / "model.json", "--json",
            d / "r.json", "--out-model", d / "model.json")
    line = one_line_error(r)
    assert r.returncode == 2 and line.count("--out-model") == 1 and "--json" not in line
    assert snapshot(d) == before


def test_json_into_a_missing_directory_names_the_directory(case, tmp_path):
    d, _, _ = case
    r = run("evaluate", d / "rec.csv", "--model", d / "model.json", "--json",
            tmp_path / "nowhere" / "e.json")
    line = one_line_error(r)
    assert r.returncode == 2 and "--json" in line and "nowhere" in line
    assert ".tmp" not in line and "create it" in line


def test_atomic_write_into_a_missing_directory_has_no_private_name(tmp_path):
    with pytest.raises(FileNotFoundError) as e:
        lugre.save_model(lugre.Model.paper(), tmp_path / "missing" / "m.json")
    assert ".tmp" not in str(e.value) and "missing" in str(e.value)


def test_huge_current_is_refused_with_row_and_column(tmp_path, case):
    d, _rec, _ = case
    p = tmp_path / "huge.csv"
    lines = (d / "rec.csv").read_text().splitlines()
    header = lines[0].split(",")
    j = header.index("i")
    cells = lines[5].split(",")
    cells[j] = "1e308"
    lines[5] = ",".join(cells)
    p.write_text("\n".join(lines) + "\n")
    with pytest.raises(FileFormatError) as e:
        read_recording(p)
    assert "line 6" in str(e.value) and "'i'" in str(e.value)
    for cmd in (["fit", p, "--force-constant", "25", "--json", tmp_path / "m.json"],
                ["evaluate", p, "--model", d / "model.json", "--json", tmp_path / "e.json"]):
        r = run(*cmd)
        line = one_line_error(r)
        assert r.returncode == 1 and "line 6" in line, line
    assert not (tmp_path / "m.json").exists() and not (tmp_path / "e.json").exists()


def test_semicolon_separated_file_gets_the_separator_hint(tmp_path):
    p = tmp_path / "semi.csv"
    p.write_text("t;x;i\n0;0;1\n0,001;0;1\n")
    with pytest.raises(FileFormatError, match="semicolons.*','"):
        read_recording(p)
    r = run("evaluate", p, "--model", "m.json", "--json", tmp_path / "e.json")
    assert "semicolons" in one_line_error(r) or "m.json" in r.stderr


def test_simulate_none_is_a_lugre_error():
    with pytest.raises(LugreError, match="lugre.Model"):
        lugre.simulate(None, np.arange(3) * 1e-3, x_ref=np.zeros(3))


def test_warnings_print_as_one_plain_line(tmp_path):
    # a model whose sigma1 breaks the passivity bound warns when it is loaded
    doc = lugre.Model.paper().to_dict()
    doc["friction"]["sigma1"] = 1e6
    (tmp_path / "m.json").write_text(json.dumps(doc))
    rec, _, _ = concealed("cogging", duration=4.0)
    write_recording(tmp_path / "rec.csv", rec)
    r = run("evaluate", tmp_path / "rec.csv", "--model", tmp_path / "m.json", "--json",
            tmp_path / "e.json")
    warn = [ln for ln in r.stderr.splitlines() if "arning" in ln]
    assert warn, r.stderr
    assert all(ln.startswith("warning: ") for ln in warn), r.stderr
    assert ".py:" not in r.stderr


def test_fit_static_says_which_values_are_placeholders(tmp_path):
    pts = points_file(tmp_path)
    r = run("fit-static", pts, "--json", tmp_path / "m.json")
    assert r.returncode == 0, r.stderr
    assert "placeholder" in r.stderr and "axis.mass" in r.stderr and "sigma0" in r.stderr
    doc = json.loads((tmp_path / "m.json").read_text())
    assert set(doc["placeholders"]["parameters"]) == {
        "axis.mass", "axis.force_constant", "friction.sigma0", "friction.sigma1"}
    lugre.load_model(tmp_path / "m.json")  # the unknown key keeps the model readable
    r = run("fit-static", pts, "--json", tmp_path / "m2.json", "--mass", "12")
    doc = json.loads((tmp_path / "m2.json").read_text())
    assert "axis.mass" not in doc["placeholders"]["parameters"]


# ---------------------------------------------------- gaps and units: refused, with fixes


@pytest.fixture(scope="module")
def gappy(tmp_path_factory):
    d = tmp_path_factory.mktemp("gappy")
    rec, believed, _ = concealed("cogging", duration=4.0)
    keep = np.random.default_rng(0).random(len(rec)) > 0.3
    keep[[0, -1]] = True
    write_recording(d / "gaps.csv", rec.slice(keep))
    mm = lugre.Recording(t=rec.t, x=rec.x * 1e3, i=rec.i, x_ref=rec.x_ref * 1e3)
    write_recording(d / "mm.csv", mm)
    lugre.save_model(believed, d / "model.json")
    return d


@pytest.mark.parametrize("cmd", ["diagnose", "evaluate", "fit"])
def test_gaps_are_refused_naming_resample(gappy, cmd, tmp_path):
    extra = ["--force-constant", "25"] if cmd == "fit" else ["--model", gappy / "model.json"]
    r = run(cmd, gappy / "gaps.csv", *extra, "--json", tmp_path / "o.json")
    line = one_line_error(r)
    assert r.returncode == 1 and "gaps" in line and "--resample" in line
    assert not (tmp_path / "o.json").exists()


@pytest.mark.parametrize("cmd", ["diagnose", "evaluate", "fit"])
def test_millimetres_are_refused_naming_x_unit(gappy, cmd, tmp_path):
    extra = ["--force-constant", "25"] if cmd == "fit" else ["--model", gappy / "model.json"]
    r = run(cmd, gappy / "mm.csv", *extra, "--json", tmp_path / "o.json")
    line = one_line_error(r)
    assert r.returncode == 1 and "--x-unit mm" in line and "x=pos/1000" in line
    assert not (tmp_path / "o.json").exists()


def test_x_unit_mm_and_column_expression_read_metres(gappy):
    a = read_recording(gappy / "mm.csv", x_unit="mm")
    b = read_recording(gappy / "mm.csv", "x=x/1000,x_ref=x_ref/1000")
    np.testing.assert_allclose(a.x, b.x)
    require_plausible(a)
    assert "mm" in a.meta["x_unit"]
    with pytest.raises(InputError, match="x_unit"):
        read_recording(gappy / "mm.csv", x_unit="inch")


def test_evaluate_with_x_unit_and_resample_runs(gappy, tmp_path):
    r = run("evaluate", gappy / "mm.csv", "--x-unit", "mm", "--model", gappy / "model.json",
            "--json", tmp_path / "e.json")
    assert r.returncode == 0, r.stderr
    r = run("evaluate", gappy / "gaps.csv", "--resample", "--model", gappy / "model.json",
            "--json", tmp_path / "e2.json")
    assert r.returncode == 0, r.stderr
    assert "resampled" in r.stdout


def test_python_entry_points_refuse_gaps(gappy):
    rec = read_recording(gappy / "gaps.csv")
    with pytest.raises(DataError, match="resample"):
        lugre.evaluate(rec, gappy / "model.json")
    with pytest.raises(DataError, match="x_unit"):
        lugre.diagnose(gappy / "mm.csv", gappy / "model.json")
    fixed = resample_uniform(rec)
    assert np.ptp(np.diff(fixed.t)) < 1e-9 and "resampled" in fixed.meta
    require_plausible(fixed)


# ------------------------------------------------------------------- tables as recordings


def test_tables_with_named_columns_are_recordings(case):
    _, rec, believed = case
    cols = {"t": rec.t, "x": rec.x, "i": rec.i}
    ref = lugre.evaluate(rec, believed)["rms_force"]
    assert lugre.evaluate(cols, believed)["rms_force"] == pytest.approx(ref)
    arr = np.zeros(len(rec), dtype=[("t", float), ("x", float), ("i", float)])
    arr["t"], arr["x"], arr["i"] = rec.t, rec.x, rec.i
    assert lugre.evaluate(arr, believed)["rms_force"] == pytest.approx(ref)

    class Frame:  # the part of a pandas DataFrame that is used
        def __init__(self, d):
            self._d = d
            self.columns = list(d)

        def __getitem__(self, k):
            return self._d[k]

    assert lugre.evaluate(Frame(cols), believed)["rms_force"] == pytest.approx(ref)
    with pytest.raises(InputError, match="no column 'x'"):
        lugre.evaluate({"t": rec.t, "i": rec.i}, believed)
    with pytest.raises(InputError, match="table with named columns"):
        lugre.evaluate(42, believed)


def test_pandas_dataframe_when_installed(case):
    pd = pytest.importorskip("pandas")
    _, rec, believed = case
    df = pd.DataFrame({"t": rec.t, "x": rec.x, "i": rec.i, "extra": 1.0})
    ref = lugre.evaluate(rec, believed)["rms_force"]
    assert lugre.evaluate(df, believed)["rms_force"] == pytest.approx(ref)


# ------------------------------------------------------------------------- fuzzed readers

_cell = st.one_of(st.floats(allow_nan=True, allow_infinity=True).map(repr),
                  st.text(alphabet="0123456789.,;-e+ \"\tx", max_size=8))


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(header=st.lists(st.sampled_from(["t", "x", "i", "F", "v", "q", ""]), min_size=1,
                       max_size=5),
       rows=st.lists(st.lists(_cell, min_size=0, max_size=6), max_size=6),
       prefix=st.sampled_from(["", "# a: b\n", "#\n\n"]))
def test_fuzzed_csv_reads_or_raises_a_lugre_error(tmp_path, header, rows, prefix):
    p = tmp_path / "f.csv"
    p.write_text(prefix + ",".join(header) + "\n" + "\n".join(",".join(r) for r in rows))
    for read in (read_recording, read_points):
        try:
            read(p)
        except LugreError:
            pass


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=st.binary(max_size=200), suffix=st.sampled_from([".csv", ".npz", ".mat"]))
def test_fuzzed_bytes_read_or_raise_a_lugre_error(tmp_path, data, suffix):
    p = tmp_path / f"b{suffix}"
    p.write_bytes(data)
    try:
        read_recording(p)
    except LugreError:
        pass


@settings(max_examples=60, deadline=None)
@given(n=st.integers(0, 5), t=st.lists(st.floats(allow_nan=True), min_size=0, max_size=5),
       spec=st.sampled_from([None, "x=t", "F=t*2", "x=q", "bad", "t="]))
def test_fuzzed_tables_and_mappings_raise_lugre_errors(n, t, spec):
    table = {"t": np.asarray(t, float), "x": np.zeros(len(t)), "i": np.ones(n)}
    try:
        lugre.io.as_recording(table, columns=spec)
    except LugreError:
        pass


def test_fits_take_tables_too(case):
    _, rec, believed = case
    cols = {"t": rec.t, "x": rec.x, "i": rec.i}
    a = lugre.fit_inverse_dynamics(rec, force_constant=believed.force_constant)
    b = lugre.fit_inverse_dynamics(cols, force_constant=believed.force_constant)
    assert a.mass == pytest.approx(b.mass)


@pytest.mark.parametrize(("extra", "option"), [
    (["--columns", "x"], "--columns"),
    (["--force-constant", "-1"], "--force-constant"),
    (["--force-constant", "abc"], "--force-constant"),
    (["--force-constant", "25", "--mass", "0"], "--mass"),
    (["--force-constant", "25", "--x-unit", "inch"], "--x-unit"),
])
def test_bad_options_are_one_line_usage_errors(case, tmp_path, extra, option):
    d, _, _ = case
    r = run("fit", d / "rec.csv", "--json", tmp_path / "m.json", *extra)
    line = one_line_error(r)
    assert r.returncode == 2 and option in line, line
    assert not (tmp_path / "m.json").exists()


def test_diagnose_band_from_the_command_line(case, tmp_path):
    d, _, _ = case
    r = run("diagnose", d / "rec.csv", "--model", d / "model.json", "--json",
            tmp_path / "r.json", "--cutoff-hz", "20", "-q")
    assert r.returncode == 0, r.stderr
    assert json.loads((tmp_path / "r.json").read_text())["noise"]["cutoff_hz"] == 20.0
    r = run("diagnose", d / "rec.csv", "--model", d / "model.json", "--json",
            tmp_path / "r2.json", "--cutoff-hz", "-5")
    assert r.returncode == 2 and "--cutoff-hz" in one_line_error(r)
