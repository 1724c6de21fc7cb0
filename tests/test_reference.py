"""Tests of the pure-Python parts: the NumPy reference, models, recordings and errors.

- (a) the reference closed loop against ``scipy.integrate.solve_ivp`` of the same ODE;
- (b) the Stribeck curve against constant-velocity data the project did not write
  (``../shared/datasets/static``);
- (c) round trips of models and recordings, and every bad input caught as both the
  package's class and the builtin ``ValueError``, with a message naming the culprit;
- the reference against the Rust-backed API when that is built.
"""

from __future__ import annotations

import json
import math
import os
import pickle
import re
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from lugre import reference
from lugre._result import SimResult
from lugre.exceptions import (
    DataError,
    FileFormatError,
    InputError,
    LugreError,
    LugreWarning,
    ModelError,
    ParameterError,
    PassivityWarning,
)
from lugre.io import Recording, read_recording, write_recording
from lugre.model import Model, _as_model, load_model, save_model
from shared_data import shared_file  # tests/data: data the project did not write

settings.register_profile("fast", max_examples=30, deadline=None)
settings.register_profile("slow", max_examples=500, deadline=None)
settings.load_profile(os.environ.get("LUGRE_HYPOTHESIS_PROFILE", "fast"))


def shared(*parts: str) -> Path:
    """A file of the test data (tests/data/datasets)."""
    return shared_file(*parts)


def model_from_truth(path: Path) -> Model:
    """The model of ``paper_axis_truth.json`` (true parameters of the static dataset)."""
    q = json.loads(path.read_text())["parameters"]
    return Model({
        "axis": {"mass": q["m"], "force_constant": q["KF"]},
        "friction": {
            "sigma0": q["s0"], "sigma1": q["s1"],
            "positive": {"fc": q["Fc_p"], "fs": q["Fs_p"], "sigma2": q["s2_p"],
                         "vs": q["vs_p"]},
            "negative": {"fc": q["Fc_n"], "fs": q["Fs_n"], "sigma2": q["s2_n"],
                         "vs": q["vs_n"]},
        },
    })


# ======================================================================================
# (a) closed loop against solve_ivp
# ======================================================================================


def closed_loop_solve_ivp(model: Model, t: np.ndarray, x_ref: np.ndarray) -> np.ndarray:
    """The PID loop of CONTRACT integrated by ``solve_ivp`` between control instants.

    ``t`` must be the control grid (``t[0] + n/rate_hz``). Returns ``(x, v, z)`` at ``t``.
    """
    from scipy.integrate import solve_ivp

    fr = model.friction
    sigma0, sigma1 = fr["sigma0"], fr["sigma1"]
    pos, neg = fr["positive"], fr["negative"]
    m, kf = model.mass, model.force_constant
    c = model.controller
    assert c is not None
    kp, ki, kd, rate = c["kp"], c["ki"], c["kd"], c["rate_hz"]

    def rhs(_t: float, y: np.ndarray, ic: float) -> list[float]:
        _x, v, z = y
        s = pos if v >= 0 else neg
        g = s["fc"] + (s["fs"] - s["fc"]) * math.exp(-((v / s["vs"]) ** 2))
        zdot = v - sigma0 * abs(v) * z / g
        friction = sigma0 * z + sigma1 * zdot + s["sigma2"] * v
        return [v, (kf * ic - friction) / m, zdot]

    y = np.array([x_ref[0], 0.0, 0.0])
    out = np.empty((t.size, 3))
    out[0] = y
    xi = 0.0
    for n in range(t.size - 1):
        xr_dot = 0.0 if n == 0 else (x_ref[n] - x_ref[n - 1]) * rate
        e = x_ref[n] - y[0]
        xi += e / rate
        ic = (kp * e + ki * xi + kd * (xr_dot - y[1])) / kf
        sol = solve_ivp(rhs, (t[n], t[n + 1]), y, method="DOP853", rtol=1e-10,
                        atol=[1e-14, 1e-12, 1e-16], args=(ic,))
        assert sol.success, sol.message
        y = sol.y[:, -1]
        out[n + 1] = y
    return out


def test_closed_loop_matches_solve_ivp() -> None:
    m = Model.paper()
    rate = m.controller["rate_hz"]  # type: ignore[index]
    t = np.arange(2001) / rate  # 0.2 s on the control grid
    x_ref = 0.002 * (1.0 - np.cos(2 * np.pi * 5.0 * t))  # out and back, one reversal
    ivp = closed_loop_solve_ivp(m, t, x_ref)
    r = reference.simulate(m, t, x_ref, integrator="rk4", substeps=10)
    span = np.ptp(ivp[:, 0])
    err_x = np.max(np.abs(r.x - ivp[:, 0])) / span
    err_v = np.max(np.abs(r.v - ivp[:, 1])) / np.ptp(ivp[:, 1])
    assert span > 3e-3  # the axis did move
    assert err_x < 1e-6, f"rk4 vs solve_ivp: max |dx| / range(x) = {err_x:.3g}"
    assert err_v < 1e-5, f"rk4 vs solve_ivp: max |dv| / range(v) = {err_v:.3g}"
    # The default integrator (exact bristle update, semi-implicit Euler) is first order
    # in x and v: close, not equal.
    ex = reference.simulate(m, t, x_ref, substeps=10)
    assert np.max(np.abs(ex.x - ivp[:, 0])) / span < 1e-3


# ======================================================================================
# (b) Stribeck curve against constant-velocity plateaus the project did not write
# ======================================================================================


def test_plateau_forces_match_stribeck_curve() -> None:
    rec = read_recording(shared("static", "paper_axis_plateaus.csv"))
    truth = model_from_truth(shared("static", "paper_axis_truth.json"))
    assert rec.v_ref is not None and rec.i is not None
    force = rec.force(truth.force_constant)
    edges = np.r_[0, np.flatnonzero(np.diff(rec.v_ref) != 0) + 1, len(rec)]
    settle = 0.5  # [s] dropped at the start of each plateau (step transient)
    rows = []
    for a, b in zip(edges[:-1], edges[1:]):
        vr = rec.v_ref[a]
        keep = slice(a + round(settle / rec.dt), b)
        t, x, f = rec.t[keep], rec.x[keep], force[keep]
        v_meas = np.polyfit(t, x, 1)[0]
        if abs(v_meas / vr - 1.0) > 0.01:
            # Below the Stribeck velocity the curve falls with speed and the loop
            # stick-slips: the mean force is no steady-state value. Skip, but only there.
            assert abs(vr) < truth.positive["vs"], f"plateau {vr} m/s does not settle"
            continue
        # Standard error of the mean with the effective sample size of an AR(1) noise.
        e = f - f.mean()
        rho = float(np.dot(e[1:], e[:-1]) / np.dot(e, e))
        n_eff = f.size * (1.0 - rho) / (1.0 + rho)
        sem = f.std(ddof=1) / math.sqrt(n_eff)
        rows.append((vr, v_meas, f.mean(), sem))
    assert len(rows) >= 8, "expected the 8 plateaus at |v| >= 0.01 m/s to be steady"
    v_meas = np.array([r[1] for r in rows])
    f_mean = np.array([r[2] for r in rows])
    sem = np.array([r[3] for r in rows])
    z_true = (f_mean - reference.stribeck(v_meas, truth)) / sem
    assert np.all(np.abs(z_true) < 4.0), (
        "plateau force - stribeck(v) in standard errors: "
        + ", ".join(f"{r[0]:+g}: {zz:+.2f}" for r, zz in zip(rows, z_true))
    )
    # The check has teeth: 1 % more viscous friction is far outside the noise.
    wrong = truth.with_friction(positive={"sigma2": 1.01 * truth.positive["sigma2"]},
                                negative={"sigma2": 1.01 * truth.negative["sigma2"]})
    z_wrong = (f_mean - reference.stribeck(v_meas, wrong)) / sem
    assert np.max(np.abs(z_wrong)) > 10.0


def test_points_file_agrees_with_stribeck_except_gross_errors() -> None:
    """``paper_axis_points.csv``: the rows not listed as gross errors lie on the curve."""
    p = shared("static", "paper_axis_points.csv")
    info = json.loads(shared("static", "paper_axis_truth.json").read_text())
    truth = model_from_truth(shared("static", "paper_axis_truth.json"))
    data = np.loadtxt(p, delimiter=",", skiprows=1)
    v, f = data[:, 0], data[:, 1]
    outliers = np.zeros(v.size, dtype=bool)
    # outlier_rows are 0-based data rows (0 is the first line after the header)
    outliers[np.asarray(info["outlier_rows"])] = True
    res = f - reference.stribeck(v, truth)
    scale = 1.4826 * np.median(np.abs(res[~outliers]))
    assert np.all(np.abs(res[~outliers]) < 5 * scale)
    assert np.median(np.abs(res[outliers])) > 10 * scale


# ======================================================================================
# Properties of the reference
# ======================================================================================


def test_friction_force_settles_on_stribeck_curve() -> None:
    m = Model.paper()
    for v in (-0.3, -0.02, 0.005, 0.05, 0.2):
        f = reference.friction_force(np.full(3000, v), 1e-3, m)
        assert f[-1] == pytest.approx(reference.stribeck([v], m)[0], rel=1e-12, abs=1e-9)


def test_friction_force_array_dt_equals_scalar_dt() -> None:
    m = Model.paper()
    v = 0.02 * np.sin(np.linspace(0, 10, 500))
    f1, z1 = reference.friction_force(v, 1e-3, m, return_z=True)
    f2, z2 = reference.friction_force(v, np.full(v.size, 1e-3), m, return_z=True)
    np.testing.assert_array_equal(f1, f2)
    np.testing.assert_array_equal(z1, z2)
    assert z1[0] == 0.0
    # F[k] is the force at the returned state z[k]
    fr = m.friction
    k = 123
    s = fr["positive"] if v[k] >= 0 else fr["negative"]
    gk = s["fc"] + (s["fs"] - s["fc"]) * math.exp(-((v[k] / s["vs"]) ** 2))
    zdot = v[k] - fr["sigma0"] * abs(v[k]) * z1[k] / gk
    assert f1[k] == pytest.approx(
        fr["sigma0"] * z1[k] + fr["sigma1"] * zdot + s["sigma2"] * v[k], rel=1e-13
    )


@given(st.lists(st.floats(-1.0, 1.0), min_size=1, max_size=200),
       st.floats(1e-6, 1.0))
def test_bristle_state_stays_bounded(v: list[float], dt: float) -> None:
    m = Model.paper()
    _, z = reference.friction_force(v, dt, m, return_z=True)
    zmax = max(m.positive["fs"], m.negative["fs"]) / m.sigma0
    assert np.all(np.abs(z) <= zmax * (1 + 1e-12))


@given(st.floats(1e-6, 2.0))
def test_stribeck_sign_and_levels(v: float) -> None:
    m = Model.paper()
    fp, fn = reference.stribeck([v, -v], m)
    assert fp > 0 > fn
    assert fp >= m.positive["fc"] + m.positive["sigma2"] * v - 1e-9
    assert -fn >= m.negative["fc"] + m.negative["sigma2"] * v - 1e-9
    assert reference.stribeck([0.0], m)[0] == 0.0


def full_model() -> Model:
    """Every effect, a current loop, a current limit and LuGre feed-forward."""
    d = Model.paper().to_dict()
    d["axis"]["current_loop"] = {"resistance": 1.2, "inductance": 0.01874,
                                 "back_emf": 25.0, "bandwidth_hz": 800.0}
    d["axis"]["current_limit"] = 12.0
    d["effects"] = [
        {"effect": "cogging", "amplitude": 1.5, "pitch": 0.025, "phase": 0.3,
         "harmonics": [[0.4, 1.0], [0.1, -0.5]]},
        {"effect": "spring", "stiffness": 200.0, "x0": 0.001},
        {"effect": "offset", "force": -2.0},
        {"effect": "position_friction", "positions": [-0.01, 0.0, 0.01],
         "scale": [0.9, 1.0, 1.2]},
        {"effect": "drift", "gain": 0.1, "time_constant": 0.2},
        {"effect": "mass", "delta": 3.0},
        {"effect": "delay", "seconds": 0.00025},
        {"effect": "current_lag", "bandwidth": 300.0},
    ]
    d["controller"]["feedforward"] = {"type": "lugre"}
    return Model(d)


def test_simulate_runs_with_every_effect_and_options() -> None:
    m = full_model()
    t = np.arange(0, 0.3, 1e-3)
    x_ref = 0.01 * np.sin(2 * np.pi * 2.0 * t)
    r = reference.simulate(m, t, x_ref)
    assert isinstance(r, SimResult) and len(r) == t.size
    assert np.max(np.abs(r.x - x_ref)) < 2e-3
    assert np.max(np.abs(r.i)) <= 12.0 + 1.0  # limit on the command, overshoot of the loop
    # open loop and pi_speed
    ro = reference.simulate(Model.paper(), t, current=np.full(t.size, 3.0), substeps=4)
    assert ro.x[-1] > 0 and np.all(np.diff(ro.x) >= -1e-12)
    pi = Model.paper().replace(controller={"type": "pi_speed", "kp": 1200.0,
                                           "ki": 12000.0, "rate_hz": 10000.0,
                                           "feedforward": {"type": "static"}})
    rv = reference.simulate(pi, t, v_ref=0.05 * np.ones(t.size))
    assert rv.v[-1] == pytest.approx(0.05, rel=2e-2)


# ======================================================================================
# The reference against the Rust-backed API (when built)
# ======================================================================================


def core_api() -> Any:
    import lugre

    if not all(hasattr(lugre, n) for n in ("simulate", "stribeck", "friction_force")):
        why = "the compiled core (lugre.simulate & co.) is not built"
        if os.environ.get("CI"):  # CI builds it: fail, whatever the words of the reason
            pytest.fail(f"in CI this must not skip: {why}")
        pytest.skip(why)
    return lugre


def test_reference_matches_core_friction() -> None:
    lugre = core_api()
    m = Model.paper()
    v = 0.05 * np.sin(np.linspace(0, 20, 2000)) + 1e-4
    np.testing.assert_allclose(lugre.stribeck(v, m), reference.stribeck(v, m),
                               rtol=1e-13, atol=1e-12)
    np.testing.assert_allclose(lugre.friction_force(v, 1e-3, m),
                               reference.friction_force(v, 1e-3, m), rtol=0, atol=1e-9)


@pytest.mark.parametrize("integrator", ["exact", "rk4"])
def test_reference_matches_core_simulation(integrator: str) -> None:
    lugre = core_api()
    t = np.arange(0, 0.2, 1e-3)
    x_ref = 0.01 * np.sin(2 * np.pi * 2.0 * t)
    for m in (Model.paper(), full_model()):
        a = lugre.simulate(m, t, x_ref, integrator=integrator, substeps=2)
        b = reference.simulate(m, t, x_ref, integrator=integrator, substeps=2)
        span = np.ptp(b.x)
        for k in ("x", "v", "z", "i", "friction", "force"):
            scale = max(np.ptp(getattr(b, k)), 1e-300)
            err = np.max(np.abs(getattr(a, k) - getattr(b, k))) / scale
            assert err < 1e-6, f"{k}: relative difference {err:.3g}"
        assert np.max(np.abs(a.x - b.x)) < 1e-6 * span


# ======================================================================================
# (c) round trips
# ======================================================================================


def test_model_json_round_trip_keeps_unknown_keys(tmp_path: Path) -> None:
    d = Model.paper().to_dict()
    d["notes"] = {"author": "bench 3", "tags": ["x", 1]}
    d["friction"]["positive"]["comment"] = "fitted 2024-03-01"
    d["effects"] = [{"effect": "cogging", "amplitude": 1.0, "pitch": 0.025,
                     "phase": 0.0, "source": "fft"}]
    m = Model(d)
    p = tmp_path / "model.json"
    save_model(m, p)
    m2 = load_model(p)
    assert m2 == m
    assert m2.to_dict()["notes"] == d["notes"]
    assert m2.positive["comment"] == "fitted 2024-03-01"
    assert m2.effects[0]["source"] == "fft"
    assert Model.from_json(m.to_json()) == m
    assert pickle.loads(pickle.dumps(m)) == m
    assert _as_model(p) == m and _as_model(d) == m and _as_model(m) is m


def test_model_is_not_changed_through_its_accessors() -> None:
    m = Model.paper()
    m.to_dict()["axis"]["mass"] = -1.0
    m.positive["fc"] = -1.0
    m.controller["kp"] = 0.0  # type: ignore[index]
    assert m.mass == 25.0 and m.positive["fc"] == 28.7 and m.controller["kp"] == 5e4  # type: ignore[index]
    m2 = m.with_friction(sigma0=2e5, negative={"vs": 0.02})
    assert (m2.sigma0, m2.negative["vs"], m2.negative["fc"]) == (2e5, 0.02, 28.5)
    assert m.sigma0 == 1e5
    assert m.replace(controller=None).controller is None
    c = m.copy()
    assert c == m and c is not m


def test_paper_model() -> None:
    m = Model.paper()
    assert (m.mass, m.force_constant, m.sigma0, m.sigma1) == (25.0, 25.0, 1e5, 31.62)
    assert m.positive == {"fc": 28.7, "fs": 60.2, "sigma2": 332.5, "vs": 0.01}
    assert m.negative == {"fc": 28.5, "fs": 60.1, "sigma2": 333.0, "vs": 0.01}
    assert m.controller == {"type": "pid", "kp": 5e4, "ki": 5e5, "kd": 1500.0,
                            "rate_hz": 10000.0}
    assert m.effects == [] and m.is_passive


def test_save_model_is_atomic(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    p = tmp_path / "model.json"
    save_model(Model.paper(), p)
    before = p.read_bytes()

    def broken_replace(src: Any, dst: Any) -> None:
        raise OSError("disk full")

    monkeypatch.setattr(os, "replace", broken_replace)
    with pytest.raises(OSError, match="disk full"):
        save_model(Model.paper().with_friction(sigma1=10.0), p)
    assert p.read_bytes() == before
    assert [f.name for f in tmp_path.iterdir()] == ["model.json"]  # no temp file left


@pytest.mark.parametrize("suffix", [".csv", ".npz", ".mat"])
def test_recording_round_trip(tmp_path: Path, suffix: str) -> None:
    rng = np.random.default_rng(1)
    n = 257
    t = np.cumsum(rng.uniform(0.5e-3, 1.5e-3, n))
    rec = Recording(t=t, x=rng.normal(size=n), i=rng.normal(size=n),
                    v=rng.normal(size=n) * 1e-7, x_ref=rng.normal(size=n) * 1e300,
                    meta={"axis": "X2", "note": "bench run 4"})
    p = tmp_path / f"rec{suffix}"
    write_recording(p, rec)
    back = read_recording(p)
    assert back.columns == ("t", "x", "i", "v", "x_ref")
    for c in back.columns:
        np.testing.assert_array_equal(getattr(back, c), getattr(rec, c))
    if suffix != ".mat":
        assert back.meta == rec.meta
    assert back.source == str(p)


def test_recording_force_and_slice() -> None:
    t = np.arange(10) * 1e-3
    rec = Recording(t=t, x=np.zeros(10), i=np.arange(10.0))
    np.testing.assert_array_equal(rec.force(25.0), 25.0 * np.arange(10.0))
    np.testing.assert_array_equal(rec.force(Model.paper()), 25.0 * np.arange(10.0))
    with pytest.raises(InputError, match="force constant"):
        rec.force()
    withF = Recording(t=t, x=np.zeros(10), F=np.ones(10))
    np.testing.assert_array_equal(withF.force(), np.ones(10))
    part = rec.slice((2e-3, 5e-3))
    np.testing.assert_array_equal(part.i, [2.0, 3.0, 4.0, 5.0])
    part2 = rec.slice(rec.i > 6)
    np.testing.assert_array_equal(part2.t, t[7:])


def test_emps_mat_with_force_expression_matches_csv_conversion() -> None:
    mat = read_recording(shared("emps", "DATA_EMPS.mat"),
                         columns={"x": "qm", "x_ref": "qg", "F": "gtau*vir"})
    csv = read_recording(shared("emps", "emps_estimation.csv"))
    assert len(mat) == len(csv) == 24841
    np.testing.assert_allclose(mat.t, csv.t, atol=1e-6)
    np.testing.assert_allclose(mat.x, csv.x, rtol=1e-5, atol=1e-8)
    np.testing.assert_allclose(mat.F, csv.F, rtol=1e-8, atol=1e-6)
    np.testing.assert_allclose(mat.x_ref, csv.x_ref, rtol=1e-6, atol=1e-10)
    same = read_recording(shared("emps", "DATA_EMPS.mat"),
                          columns=["x=qm", "x_ref=qg", "F=gtau * vir"])
    np.testing.assert_array_equal(same.F, mat.F)


def test_mat_without_time_uses_sample_time(tmp_path: Path) -> None:
    import scipy.io

    p = tmp_path / "rec.mat"
    scipy.io.savemat(p, {"pos": np.arange(5.0), "cur": np.ones(5), "Ts": 1e-3})
    rec = read_recording(p, columns={"x": "pos", "i": "cur"})
    np.testing.assert_allclose(rec.t, np.arange(5) * 1e-3)
    assert "Ts" in rec.meta["t"]


def test_csv_metadata_and_columns_in_any_order(tmp_path: Path) -> None:
    p = tmp_path / "r.csv"
    p.write_text("# axis: Y\n# free text line\n# kf: 25\nF, extra,t,x\n"
                 "1.0,a,0.0,0.0\n2.0,b,0.001,1e-6\n\n")
    rec = read_recording(p)
    assert rec.meta == {"axis": "Y", "kf": "25"}
    np.testing.assert_array_equal(rec.F, [1.0, 2.0])
    assert rec.i is None


# ======================================================================================
# (c) every bad input: package class and builtin, message naming the culprit
# ======================================================================================


def raises_both(cls: type[LugreError], match: str) -> Any:
    """``pytest.raises`` for ``cls`` that also checks it is a ``ValueError``."""
    assert issubclass(cls, ValueError) and issubclass(cls, LugreError)
    return pytest.raises(cls, match=match)


def changed(path: str, value: Any) -> dict[str, Any]:
    """The paper model's dict with ``path`` (dot-separated) set to ``value``."""
    d = Model.paper().to_dict()
    *head, last = path.split(".")
    node = d
    for k in head:
        node = node[k]
    node[last] = value
    return d


@pytest.mark.parametrize(
    ("path", "value", "name"),
    [
        ("axis.mass", 0.0, "axis.mass"),
        ("axis.mass", -25.0, "axis.mass"),
        ("axis.mass", math.nan, "axis.mass"),
        ("axis.force_constant", math.inf, "axis.force_constant"),
        ("friction.sigma0", 0.0, "friction.sigma0"),
        ("friction.sigma0", -1e5, "friction.sigma0"),
        ("friction.sigma1", -1.0, "friction.sigma1"),
        ("friction.positive.vs", 0.0, "friction.positive.vs"),
        ("friction.negative.vs", -0.01, "friction.negative.vs"),
        ("friction.negative.fs", 20.0, "friction.negative.fs"),  # fs < fc
        ("friction.positive.sigma2", -1.0, "friction.positive.sigma2"),
        ("friction.positive.fc", math.nan, "friction.positive.fc"),
        ("controller.rate_hz", 0.0, "controller.rate_hz"),
    ],
)
def test_parameter_errors_name_the_parameter(path: str, value: float, name: str) -> None:
    with raises_both(ParameterError, re.escape(name)) as info:
        Model(changed(path, value))
    assert info.value.name == name
    with pytest.raises(ValueError, match=re.escape(name)):
        Model(changed(path, value))


def test_fs_below_fc_says_how_to_fix() -> None:
    with raises_both(ParameterError, "at least fc"):
        Model(changed("friction.positive.fs", 10.0))


@pytest.mark.parametrize(
    ("mutate", "where"),
    [
        (lambda d: d["friction"]["negative"].pop("vs"), "friction.negative.vs"),
        (lambda d: d.pop("axis"), "axis"),
        (lambda d: d["axis"].__setitem__("mass", "heavy"), "axis.mass"),
        (lambda d: d["axis"].__setitem__("mass", True), "axis.mass"),
        (lambda d: d.__setitem__("effects", [{"effect": "cogging", "amplitude": 1,
                                              "pitch": 0.1}, {"effect": "magic"}]),
         "effects[1].effect"),
        (lambda d: d.__setitem__("effects", {"effect": "spring"}), "effects"),
        (lambda d: d["controller"].__setitem__("type", "lqr"), "controller.type"),
        (lambda d: d["friction"].__setitem__("model", "dahl"), "friction.model"),
    ],
)
def test_model_errors_name_the_path(mutate: Any, where: str) -> None:
    d = Model.paper().to_dict()
    mutate(d)
    with raises_both(ModelError, re.escape(where)) as info:
        Model(d)
    assert info.value.path == where


def test_effect_parameter_errors_name_the_effect_index() -> None:
    d = Model.paper().to_dict()
    d["effects"] = [{"effect": "offset", "force": 1.0},
                    {"effect": "spring", "stiffness": 1.0},
                    {"effect": "cogging", "amplitude": 1.0, "pitch": -0.02}]
    with raises_both(ParameterError, re.escape("effects[2].pitch")):
        Model(d)
    d["effects"] = [{"effect": "mass", "delta": -30.0}]
    with raises_both(ParameterError, re.escape("effects.mass.delta")):
        Model(d)
    d["effects"] = [{"effect": "position_friction", "positions": [0.0, 0.0],
                     "scale": [1.0, 1.0]}]
    with raises_both(ModelError, re.escape("effects[0].positions[1]")):
        Model(d)


def test_passivity_warning() -> None:
    with pytest.warns(PassivityWarning, match="sigma1"):
        m = Model.paper().with_friction(sigma1=2000.0)
    assert not m.is_passive
    assert issubclass(PassivityWarning, LugreWarning) and issubclass(LugreWarning, UserWarning)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        Model.paper()  # the paper's axis is passive: no warning


def test_load_model_errors_name_the_file(tmp_path: Path) -> None:
    missing = tmp_path / "nope.json"
    with pytest.raises(FileNotFoundError, match="nope.json"):
        load_model(missing)
    bad = tmp_path / "bad.json"
    bad.write_text("{ not json")
    with raises_both(ModelError, "bad.json.*not valid JSON"):
        load_model(bad)
    neg = tmp_path / "neg.json"
    neg.write_text(json.dumps(changed("friction.negative.vs", -0.01)))
    with raises_both(ParameterError, r"neg\.json.*friction\.negative\.vs") as info:
        load_model(neg)
    assert info.value.name == "friction.negative.vs"


T = np.arange(0, 0.01, 1e-3)
XR = 1e-3 * T


@pytest.mark.parametrize(
    ("kwargs", "name", "match"),
    [
        ({"t": T, "x_ref": np.r_[XR[:3], np.nan, XR[4:]]}, "x_ref", "element 3 is NaN"),
        ({"t": T, "x_ref": np.r_[XR[:5], np.inf, XR[6:]]}, "x_ref", "element 5 is inf"),
        ({"t": np.r_[T[:2], np.inf, T[3:]], "x_ref": XR}, "t", "element 2 is inf"),
        ({"t": T, "x_ref": XR[:-1]}, "x_ref", "has 9 samples but t has 10"),
        ({"t": [], "x_ref": []}, "t", "is empty"),
        ({"t": np.r_[T[:4], T[3], T[5:]], "x_ref": XR}, "t", "not strictly increasing at element 4"),
        ({"t": T[::-1], "x_ref": XR}, "t", "not strictly increasing at element 1"),
        ({"t": T, "current": np.ones(5)}, "i", "has 5 samples"),
        ({"t": T, "v_ref": XR}, "v_ref", "position PID"),
        ({"t": T}, "x_ref", "nothing drives"),
        ({"t": T, "x_ref": XR, "integrator": "euler"}, "integrator", "unknown integrator"),
    ],
)
def test_simulate_input_errors(kwargs: dict[str, Any], name: str, match: str) -> None:
    with raises_both(InputError, match) as info:
        reference.simulate(Model.paper(), **kwargs)
    assert info.value.name == name
    assert str(info.value).startswith(f"input {name}: ")


def test_simulate_option_and_model_errors() -> None:
    with raises_both(ParameterError, "substeps"):
        reference.simulate(Model.paper(), T, XR, substeps=0)
    with raises_both(ParameterError, "z0"):
        reference.simulate(Model.paper(), T, XR, z0=math.nan)
    with raises_both(ModelError, "controller"):
        reference.simulate(Model.paper().replace(controller=None), T, XR)
    with raises_both(ParameterError, "axis.mass"):
        reference.simulate(changed("axis.mass", 0.0), T, XR)  # a dict is validated too
    with raises_both(DataError, "diverged"):
        unstable = Model.paper().replace(controller={"type": "pid", "kp": 5e9,
                                                     "rate_hz": 100.0})
        reference.simulate(unstable, np.arange(0, 1, 1e-2), np.full(100, 0.01), x0=0.0)


def test_friction_input_errors() -> None:
    m = Model.paper()
    with raises_both(InputError, "input v: element 1 is NaN"):
        reference.stribeck([0.1, math.nan], m)
    with raises_both(InputError, "input v: element 0 is inf"):
        reference.friction_force([math.inf], 1e-3, m)
    with raises_both(InputError, "input dt: has 2 samples but v has 3"):
        reference.friction_force([0.1, 0.2, 0.3], [1e-3, 1e-3], m)
    with raises_both(InputError, "input dt"):
        reference.friction_force([0.1], -1e-3, m)


def write(tmp_path: Path, text: str, name: str = "rec.csv") -> Path:
    p = tmp_path / name
    p.write_text(text)
    return p


def test_recording_missing_column_lists_columns_and_suggests_mapping(tmp_path: Path) -> None:
    p = write(tmp_path, "# run: 1\nt,pos,i\n0,0,1\n0.001,0,1\n")
    with raises_both(FileFormatError, r"no column 'x'") as info:
        read_recording(p)
    msg = str(info.value)
    assert "rec.csv" in msg and "t, pos, i" in msg and "'x': 'pos'" in msg
    assert read_recording(p, columns="x=pos").x.tolist() == [0.0, 0.0]
    p2 = write(tmp_path, "t,x,u\n0,0,1\n0.001,0,1\n", "nof.csv")
    with raises_both(FileFormatError, r"nof\.csv.*no column 'i'.*or 'F'"):
        read_recording(p2)
    with raises_both(FileFormatError, r"mapping gives x=qm.*no column 'qm'"):
        read_recording(p, columns={"x": "qm"})


def test_recording_non_numeric_cell_names_line_and_column(tmp_path: Path) -> None:
    p = write(tmp_path, "# a comment\nt,x,i\n0,0,1\n0.001,0,1\n0.002,abc,1\n")
    with raises_both(FileFormatError, r"rec\.csv, line 5, column 'x': 'abc' is not a number") as info:
        read_recording(p)
    assert (info.value.row, info.value.column) == (5, "x")


def test_recording_time_not_increasing_names_the_row(tmp_path: Path) -> None:
    p = write(tmp_path, "t,x,i\n0,0,1\n0.001,0,1\n0.001,0,1\n")
    with raises_both(FileFormatError, r"rec\.csv, line 4, column 't': time is not strictly"):
        read_recording(p)


def test_recording_other_file_errors(tmp_path: Path) -> None:
    with pytest.raises(FileNotFoundError, match="absent.csv"):
        read_recording(tmp_path / "absent.csv")
    with raises_both(FileFormatError, "line 3: 2 values for the 3 columns"):
        read_recording(write(tmp_path, "t,x,i\n0,0,1\n0.001,0\n"))
    with raises_both(FileFormatError, "line 2, column 'i'.*not finite"):
        read_recording(write(tmp_path, "t,x,i\n0,0,nan\n"))
    with raises_both(FileFormatError, "no data rows"):
        read_recording(write(tmp_path, "# only\nt,x,i\n"))
    np.savez(tmp_path / "r.npz", t=np.arange(3.0), x=np.zeros(4), i=np.zeros(3))
    with raises_both(FileFormatError, "column 'x'.*4 samples but t has 3"):
        read_recording(tmp_path / "r.npz")
    with pytest.raises(ValueError, match="not a recording column"):
        read_recording(tmp_path / "r.npz", columns={"position": "x"})


def test_recording_constructor_errors() -> None:
    with raises_both(InputError, "input x: has 2 samples but t has 3"):
        Recording(t=[0, 1, 2], x=[0, 1], i=[0, 0, 0])
    with raises_both(InputError, "input i: .*current i or the motor force F"):
        Recording(t=[0, 1], x=[0, 1])
    with raises_both(InputError, "input t: time is not strictly increasing at element 2"):
        Recording(t=[0, 1, 1], x=[0, 1, 2], F=[0, 0, 0])


def test_exceptions_pickle_with_attributes() -> None:
    e = ParameterError.invalid("axis.mass", 0.0, "must be greater than zero")
    e2 = pickle.loads(pickle.dumps(e))
    assert (type(e2), str(e2), e2.name, e2.value) == (ParameterError, str(e), "axis.mass", 0.0)
    f = FileFormatError("bad", path="a.csv", row=3, column="t")
    f2 = pickle.loads(pickle.dumps(f))
    assert (f2.path, f2.row, f2.column) == ("a.csv", 3, "t")
    # the plain one-argument form used by the bindings works too
    assert ParameterError("msg").name is None

