"""Diagnosis on concealed-effect recordings (lugre.diagnosis.synth) and on bad input."""

from __future__ import annotations

import json
import re

import lugre
import numpy as np
import pytest
from lugre.diagnosis import diagnose, evaluate, fit_inverse_dynamics, write_plots
from lugre.diagnosis.scoring import accept, accept_many, block_evidence
from lugre.diagnosis.synth import concealed
from lugre.exceptions import DataError


@pytest.fixture(scope="module")
def cogging_case():
    rec, believed, _truth = concealed("cogging", duration=10.0)
    hold, _, _ = concealed("cogging", duration=10.0, seed=5)
    return rec, believed, diagnose(rec, believed, holdout=hold, closed_loop=False)


def test_report_shape_and_plots(cogging_case, tmp_path):
    rec, believed, dg = cogging_case
    d = json.loads(dg.to_json())
    f = d["findings"][0]
    assert set(f) >= {"effect", "parameters", "where", "explained", "evidence"}
    assert set(f["where"]) == {"position", "time", "velocity"}
    assert 0.3 < f["explained"] <= 1.0
    assert set(d["fit"]) >= {"before", "after", "holdout_before", "holdout_after"}
    aug = dg.augmented_model()
    assert any(e["effect"] == "cogging" for e in aug.effects)
    assert evaluate(rec, aug)["rms_force"] < evaluate(rec, believed)["rms_force"]
    assert "cogging" in dg.summary()
    files = write_plots(dg, tmp_path)
    assert {p.name for p in files} >= {"residual_time.png", "residual_position.png",
                                       "residual_velocity.png", "residual_spectrum.png",
                                       "overlay.png"}
    assert all(p.stat().st_size > 1000 for p in files)


def _near(x, truth, *, rel=None, abs_=None):
    return x == pytest.approx(truth, rel=rel, abs=abs_)


# Every effect of the vocabulary, concealed in a 10 s record (synth.EFFECTS: small against
# friction, 10 mA current noise, spikes, 1 um encoder, base off ~1 %), checked by name,
# key parameters within the stated tolerance and the gain on a second record (seed 5).
# Tolerances are those the generator allows: its current is an instantaneous 1 kHz sample
# of a 10 kHz loop (aliasing reads as an apparent lead of ~0.5 ms, so a delay comes out
# ~0.5 ms short), and the mass effect is measured against the re-estimated base mass.
EVERY = ["none", "cogging", "spring", "offset", "position_friction", "drift", "mass",
         "delay", "current_lag"]


@pytest.mark.parametrize("effect", EVERY)
def test_every_effect_of_the_vocabulary(effect):
    rec, believed, truth = concealed(effect, duration=10.0)
    hold, _, _ = concealed(effect, duration=10.0, seed=5)
    dg = diagnose(rec, believed, holdout=hold, closed_loop=False)
    names = [f.effect for f in dg.findings]
    before = dg.fit["holdout_before"]["rms_force"]
    after = dg.fit["holdout_after"]["rms_force"]
    if effect == "none":
        assert names == []
        assert after <= before * 1.001
        return
    assert after <= 0.7 * before
    e = truth.effects[0]
    f = dg.findings[0]
    alt = {a["effect"]: a["parameters"] for a in f.alternatives}
    if effect in ("delay", "current_lag"):
        # same first-order signature: a delay when the record cannot tell them apart
        # (the lag beside it), the lag when its attenuation shows
        assert names == [f.effect] and f.effect in ("delay", effect)
        assert {f.effect, *alt} <= {"delay", "current_lag"}
        if f.effect != effect:
            assert effect in alt
        p = f.parameters if f.effect == effect else alt[effect]
    else:
        assert names == [effect]
        p = f.parameters
    if effect == "cogging":
        assert _near(p["pitch"], e["pitch"], rel=0.01)
        assert _near(p["amplitude"], e["amplitude"], rel=0.1)
        assert _near(p["phase"], e["phase"], abs_=0.1)
    elif effect == "spring":
        assert _near(p["stiffness"], e["stiffness"], rel=0.1)
        assert _near(p["x0"], e["x0"], abs_=0.01)
    elif effect == "offset":
        assert _near(p["force"], e["force"], rel=0.1)
    elif effect == "position_friction":
        s_est = np.interp(e["positions"], p["positions"], p["scale"])
        assert np.max(np.abs(s_est - np.array(e["scale"]))) < 0.1
        lo, hi = f.where["position"]
        assert lo < -0.03 < hi
    elif effect == "drift":
        assert _near(p["gain"], e["gain"], rel=0.1)
        assert _near(p["time_constant"], e["time_constant"], rel=0.2)
        assert f.uncertainty["time_constant_determined"]
    elif effect == "mass":
        assert _near(p["delta"], e["delta"], rel=0.15)
    elif effect == "delay":
        assert _near(p["seconds"], e["seconds"], rel=0.3)
    elif effect == "current_lag":
        assert _near(p["bandwidth"], e["bandwidth"], rel=0.2)


def test_offset_against_asymmetric_levels():
    """One constant force is preferred to four moved Coulomb/static levels; the evidence
    counts the moves of both stories and names the separating experiment's idea."""
    rec, believed, _ = concealed("offset", duration=10.0, seed=2)
    dg = diagnose(rec, believed, closed_loop=False)
    assert [f.effect for f in dg.findings] == ["offset"]
    f = dg.findings[0]
    assert "asymmetric Coulomb/static levels" in f.evidence
    assert all(abs(b["change"]) < 3 * b["tolerance"] for b in dg.base.values()
               if b is not dg.base["sigma1"])
    # without the candidate, the levels move in opposite senses by about the offset
    dg0 = diagnose(rec, believed, closed_loop=False, candidates=["mass"])
    b = dg0.base
    assert b["positive.fc"]["after"] - b["positive.fc"]["before"] > 2.0
    assert b["negative.fc"]["after"] - b["negative.fc"]["before"] < -2.0
    note = next(n for n in dg0.notes if "constant force of" in n)
    assert float(re.search(r"constant force of ([-0-9.]+) N", note)[1]) == pytest.approx(
        3.0, rel=0.15)


def test_drift_slower_than_the_record_reports_the_rate():
    """tau = 60 s in a 10 s record: gain and tau trade off; the change over the record
    (a trend) is what the record determines."""
    eff = {"effect": "drift", "gain": 0.3, "time_constant": 60.0}
    rec, believed, _ = concealed(eff, duration=10.0)
    dg = diagnose(rec, believed, closed_loop=False)
    assert [f.effect for f in dg.findings] == ["drift"]
    u = dg.findings[0].uncertainty
    assert not u["time_constant_determined"]
    lo, hi = u["change_over_record"]
    change = 0.3 * (1 - np.exp(-10.0 / 60.0))  # 4.6 %
    assert 0.85 * change < lo <= hi < 1.15 * change
    assert "not determined" in dg.findings[0].evidence


def test_evaluate_reports_a_friction_level_change_and_an_offset():
    """The true model leaves no level shift; a model with both Coulomb levels 8 % low
    (friction changed since its record) and one with an added constant force show each
    for what it is, at its size."""
    rec, _, truth = concealed("none", duration=6.0)
    ls = evaluate(rec, truth)["level_shift"]
    assert not ls["significant"] and ls["kind"] is None
    low = truth.replace(friction={**truth.friction, **{
        d: {**truth.friction[d], "fc": 0.92 * truth.friction[d]["fc"]}
        for d in ("positive", "negative")}})
    ls = evaluate(rec, low)["level_shift"]
    assert ls["kind"] == "friction level"
    for d in ("positive", "negative"):
        assert ls[d]["shift"] == pytest.approx(0.08 * truth.friction[d]["fc"], rel=0.25)
    off = truth.replace(effects=[{"effect": "offset", "force": 2.0}])
    ls = evaluate(rec, off)["level_shift"]
    assert ls["kind"] == "constant force"
    assert ls["positive"]["shift"] == pytest.approx(-2.0, rel=0.25)
    assert ls["negative"]["shift"] == pytest.approx(2.0, rel=0.25)


def test_evaluate_keys():
    rec, believed, truth = concealed("none", duration=4.0)
    e = evaluate(rec, truth)
    assert e["rms_force"] > 0 and 0 < e["nrmse_force"] < 0.05
    assert e["rms_force"] < evaluate(rec, believed)["rms_force"] * 1.01


def test_fit_inverse_dynamics_recovers_mass_and_viscous():
    rec, _, _truth = concealed("none", duration=10.0)
    m = fit_inverse_dynamics(rec, force_constant=25.0)
    assert m.mass == pytest.approx(25.0, rel=0.05)
    assert m.positive["sigma2"] == pytest.approx(332.5, rel=0.1)


def _rec(**kw):
    t = np.arange(2000) * 1e-3
    base = {"t": t, "x": 0.05 * np.sin(2 * np.pi * t), "i": np.ones_like(t)}
    base.update(kw)
    return lugre.Recording(**base)


def test_bad_input():
    m = lugre.Model.paper()
    with pytest.raises(DataError, match="no motion"):
        diagnose(_rec(x=np.zeros(2000)), m)
    with pytest.raises(DataError, match="samples"):
        diagnose(lugre.Recording(t=np.arange(100) * 1e-3, x=np.zeros(100), i=np.ones(100)), m)
    with pytest.raises(DataError, match="one direction"):
        diagnose(_rec(x=np.linspace(0, 0.1, 2000)), m)
    t = np.arange(2000) * 1e-3
    with pytest.raises(DataError, match="millimetres.*--x-unit mm"):
        evaluate(_rec(x=50.0 * np.sin(2 * np.pi * t)), m)
    keep = np.sort(np.random.default_rng(0).permutation(2000)[:1400])  # 30 % rows lost
    with pytest.raises(DataError, match=r"gaps.*--resample"):
        diagnose(lugre.Recording(t=t[keep], x=0.05 * np.sin(2 * np.pi * t[keep]),
                                 i=np.ones(1400)), m)
    with pytest.raises(FileNotFoundError):
        diagnose("/nonexistent/recording.csv", m)


@pytest.mark.parametrize("eff,key,rel", [
    ({"effect": "mass", "delta": 1.2}, "delta", 0.3),        # payload of 5 % on 25 kg
    ({"effect": "delay", "seconds": 0.0005}, "seconds", 0.3),  # dead time under a sample
    ({"effect": "current_lag", "bandwidth": 150.0}, "bandwidth", 0.3),
])
def test_payload_and_timing_named(eff, key, rel):
    rec, believed, _ = concealed(eff, duration=10.0)
    dg = diagnose(rec, believed, closed_loop=False)
    assert len(dg.findings) == 1
    f = dg.findings[0]
    cands = {f.effect: f.parameters, **{a["effect"]: a["parameters"] for a in f.alternatives}}
    assert eff["effect"] in cands, (f.effect, f.alternatives)
    assert cands[eff["effect"]][key] == pytest.approx(eff[key], rel=rel)
    if eff["effect"] == "delay":
        assert f.effect == "delay"  # not told apart: the time shift is named


def test_bristles_at_the_sample_instants():
    """The residual's friction at the samples of a finely simulated axis: advanced with the
    velocity at the middle of each interval it matches the plant's friction; advanced with
    v[k-1] held (a half-interval lag) it is off by about sigma0*v*dt/2 in presliding."""
    from lugre.diagnosis import residual as R

    m = lugre.Model.paper()
    t = np.arange(40000) * 1e-4  # 10 kHz plant, open loop through reversals
    i = 2.0 * np.sin(2 * np.pi * 1.0 * t)
    s = lugre.simulate(m, t, current=i)
    rec = lugre.Recording(t=t[::10], x=s.x[::10], i=i[::10])
    sig = R.prepare(rec, m, drive_cutoff_hz=499.0)
    sig = sig.with_drive(s.v[::10])  # the exact velocity: only the bristle timing differs
    new = R.base_friction(m, sig)
    old = lugre.friction_force(sig.v, sig.dt, m)
    true = s.friction[::10]
    k = sig.mask
    e_new = np.sqrt(np.mean((new - true)[k] ** 2))
    e_old = np.sqrt(np.mean((old - true)[k] ** 2))
    assert e_new < 0.3 * e_old, (e_new, e_old)


def test_a_current_logged_through_a_rippling_force_constant_is_a_force_ripple():
    """The recorded current is the actual one times 1 + 5 % sin(2 pi x / 30 mm): the
    force the axis gets is the recorded current's times 1/(1 + 5 % sin), a force
    ripple of about 5 % at a 30 mm pitch (position_friction resembles it in part)."""
    from lugre.diagnosis.synth import case

    rec, _hold, believed, _ = case([], seed=900, kind="sines", duration=20.0)
    g = 1 + 0.05 * np.sin(2 * np.pi * rec.x / 0.03)
    rec = lugre.Recording(t=rec.t, x=rec.x, i=rec.i * g, x_ref=rec.x_ref)
    dg = diagnose(rec, believed, closed_loop=False)
    assert [f.effect for f in dg.findings] == ["force_ripple"], dg.summary()
    p = dg.findings[0].parameters
    assert p["pitch"] == pytest.approx(0.03, rel=0.03)
    assert p["amplitude"] == pytest.approx(0.05, rel=0.3)
    # 1/(1 + a sin(u)) ~ 1 + a sin(u + pi): the phase is half a turn off
    assert abs((p["phase"] - np.pi + np.pi) % (2 * np.pi) - np.pi) < 0.3


@pytest.mark.parametrize("effect", ["none", "cogging"])
def test_fast_sampling_keeps_the_band_the_position_reading_allows(effect):
    # at 10 kHz the usual fs/25 band (400 Hz) would carry about a hundred times the
    # acceleration noise of the 1 µm encoder (twice differentiated, times the mass);
    # a compliant load smooths the acceleration and "explained" it: a resonance named
    # on a clean record. The band now ends where the reading's noise would dominate.
    from lugre.diagnosis import residual as R

    rec, believed, _ = concealed(None if effect == "none" else effect, duration=4.0,
                                 rate_hz=10000.0)
    sig = R.prepare(rec, believed)
    assert 40.0 < sig.cutoff_hz < 100.0
    assert sig.info["reading_band_hz"] == pytest.approx(sig.cutoff_hz)
    # at 1 kHz the same axis keeps fs/25
    rec1, believed1, _ = concealed(None, duration=4.0)
    assert R.prepare(rec1, believed1).cutoff_hz == pytest.approx(40.0)
    dg = diagnose(rec, believed, closed_loop=False)
    assert [f.effect for f in dg.findings] == ([] if effect == "none" else ["cogging"])
    if effect == "none":
        assert dg.unexplained is None
    # the noise floor follows the reading's f^4 noise: it matches what the measurements
    # alone give (a flat floor read 0.04 N where they give 0.056 N)
    # (the 4 s cogging record keeps a rest after its finding, 0.16 N rms, which lifts
    # its floor to twice; the clean record's floor is the measurements' own)
    noise = dg.noise
    if effect == "none":
        assert 0.85 < noise["rms"] / noise["expected_rms"] < 1.3
    else:
        assert noise["rms"] < 3.0 * noise["expected_rms"]


def test_resonance_search_stays_in_its_box():
    # the staged search walks the lattice from the best point; it must not walk out of
    # the band or into overdamped couplings (a damping ratio of 2.3 was once named)
    from lugre.diagnosis import candidates as E
    from lugre.diagnosis import residual as R

    rec, believed, _ = concealed(None, duration=4.0)
    sig = R.prepare(rec, believed)
    ctx = E.Context.build(sig, believed)
    c = E.Resonance()
    grid = c.grid(ctx)
    top = 0.8 * sig.cutoff_hz
    assert len(grid) == 14 and max(h[0] for h in grid) == pytest.approx(top)
    rows = [(h, float(k)) for k, h in enumerate(grid[::-1])]  # the top frequency best
    seen = list(rows)
    for stage in range(1, 8):
        nxt = c.next_grid(seen, grid, stage)
        if nxt is None:
            break
        # each new point scores better the higher its frequency and damping
        seen += [(h, -h[0] - 100 * h[1] - stage) for h in nxt]
    hs = [h for h, _ in seen]
    assert max(h[0] for h in hs) <= 1.13 * top + 1e-9
    assert max(h[1] for h in hs) <= 1.6 * 0.3 + 1e-9
    assert len(hs) < 171  # fewer load simulations than the full product grid


def test_scores_read_on_every_step_th_sample_agree():
    # a long record's held-out scores read every step-th sample: the filtered columns
    # are band-limited, so the sums agree with the full ones (and a cogging term's
    # gain with them)
    from lugre.diagnosis import base as B
    from lugre.diagnosis import candidates as E
    from lugre.diagnosis import residual as R
    from lugre.diagnosis.candidates import Term
    from lugre.diagnosis.scoring import Scorer
    from lugre.diagnosis.search import make_term

    rec, believed, _ = concealed("cogging", duration=10.0)
    sig = R.prepare(rec, believed)
    r0 = R.residual(believed, sig)
    J, _, _, tol = B.base_jacobian(believed, sig, names=B.LEVELS)
    ctx = E.Context.build(sig, believed)
    step = sig.rows_step
    assert step == 5
    ctx.extra["rows_step"] = step
    cog = next(c for c in E.candidates() if c.effect == "cogging")
    full = make_term(cog, 0.03, ctx)
    rows = make_term(cog, 0.03, ctx, rows=True)
    assert rows.X.shape[0] == -(-len(sig) // step)
    noise = R.noise_floor(r0, sig)
    s2 = noise["rms"] ** 2 * sig.mask.sum() / noise["n_eff"]
    s1 = Scorer(r0, J, tol, sig.mask, s2, 10)
    s5 = Scorer(r0, J, tol, sig.mask, s2, 10, step=step)
    for terms5, terms1 in (([], []), ([rows], [full])):
        a, b = s1.evaluate(terms1), s5.evaluate(terms5)
        assert b.score == pytest.approx(a.score, rel=2e-3)
    q = J.shape[1]  # the cogging's sine and cosine amplitudes
    assert b.beta[q:] == pytest.approx(a.beta[q:], rel=2e-3)
    gain1 = s1.evaluate([]).score - s1.evaluate([full]).score
    gain5 = s5.evaluate([]).score - s5.evaluate([rows]).score
    assert gain5 == pytest.approx(gain1, rel=2e-3)
    assert isinstance(full, Term)


@pytest.mark.parametrize("seconds", [None, 0.0003, 0.001])
def test_dead_time_read_beyond_the_controllers_hold(seconds):
    # the model's 10 kHz controller holds each command for 0.1 ms, so the force follows
    # the logged commands by 0.05 ms: the diagnosis reads the current that much later
    # and a dead time comes back as what the drive adds beyond the hold (before, a
    # clean 10 kHz record could show its own hold as a delay, and 0.3 ms read 0.21 ms)
    from lugre.diagnosis.residual import command_hold

    eff = None if seconds is None else {"effect": "delay", "seconds": seconds}
    rec, believed, _ = concealed(eff, duration=6.0, rate_hz=10000.0)
    assert command_hold(believed) == pytest.approx(0.5 / believed.controller["rate_hz"])
    dg = diagnose(rec, believed, closed_loop=False)
    timing = [f for f in dg.findings if f.effect in ("delay", "current_lag")]
    if seconds is None:
        assert timing == []
        return
    assert [f.effect for f in timing] == ["delay"]
    f = timing[0]
    assert f.parameters["seconds"] == pytest.approx(seconds, rel=0.1)
    assert f.uncertainty["controller_hold_s"] == pytest.approx(command_hold(believed))
    # without a controller nothing is known of a hold: none is assumed
    assert command_hold(believed.replace(controller=None)) == 0.0


@pytest.mark.parametrize("eff", [{"effect": "current_lag", "bandwidth": 200.0},
                                 {"effect": "deadband", "current": 0.02}])
def test_lookalikes_decided_by_their_exact_forms(eff):
    # a 200 Hz current lag logged at 10 kHz and an amplifier dead-band both act where
    # the current swings through zero; by its linearised gain the dead-band came first
    # and a lag was named a dead-band (14 mA). Refitted exactly, each story is told by
    # the one that fits: the lag's family for the lag, the dead-band for the dead-band
    rec, believed, _ = concealed(eff, duration=10.0, rate_hz=10000.0)
    dg = diagnose(rec, believed, closed_loop=False)
    names = [f.effect for f in dg.findings]
    if eff["effect"] == "deadband":
        assert names == ["deadband"]
        assert dg.findings[0].parameters["current"] == pytest.approx(0.02, rel=0.1)
        return
    assert len(names) == 1 and names[0] in ("delay", "current_lag")
    f = dg.findings[0]
    # the same mean delay whichever form, given in seconds by both: 1/(2 pi 200 Hz)
    assert f.parameters["seconds"] == pytest.approx(1.0 / (2 * np.pi * 200.0), rel=0.2)
    # a lag's bandwidth is given whenever a lag is a reading the record allows: named,
    # or beside a delay it is not told apart from (then the alternative's fitted value)
    lag = [a for a in f.alternatives if a["effect"] == "current_lag"]
    if f.effect == "current_lag":
        assert f.parameters["seconds"] == pytest.approx(
            1.0 / (2 * np.pi * f.parameters["bandwidth"]), rel=1e-12)
    elif lag:
        assert f.parameters["bandwidth"] == lag[0]["parameters"]["bandwidth"]
    else:
        assert "bandwidth" not in f.parameters
    trials = [g for g in dg.trials if g["effect"] == "deadband" and g["step"] == 1]
    assert trials and trials[0]["ok"]  # the dead-band did pass: the exact forms decided


@pytest.mark.parametrize("seed", [11, 20072])
def test_light_axis_logged_fast_has_nothing_to_find(seed):
    # a 6.7 kg axis with a 1 um encoder logged at 5 kHz, diagnosed against the exact
    # model that made it: its quantised position, twice differentiated, sweeps through
    # the band near every reversal, and with the band reaching where that noise was
    # twice the current's, a damped 38 Hz resonance "explained" it (it smooths the
    # acceleration). The band now ends where the two readings' noises are equal.
    from lugre.diagnosis.synth import case

    rec, _hold, _bel, truth = case([], seed=seed, axis_seed=4035, kind="sines",
                                   duration=10.0, rate_hz=5000.0, current_noise=0.006,
                                   quantum=1e-6, base_error=0.0)
    dg = diagnose(rec, truth, closed_loop=False)
    assert dg.findings == []
    assert dg.unexplained is None


def test_unphysical_terms_are_no_candidates():
    # on this light axis's feeds a negative drag fits the dead-band's column at low
    # speed; taken as a rival and refitted it made an invalid model and the diagnosis
    # failed ("effects[0].coefficient = -95 must be zero or greater"). A term whose
    # effect the model would refuse is not physical and not a candidate.
    from lugre.diagnosis.synth import case

    eff = {"effect": "deadband", "current": 0.0023}
    rec, _hold, believed, _ = case([eff], seed=20054, axis_seed=7502, kind="feeds",
                                   duration=6.0, rate_hz=5000.0, current_noise=0.0041,
                                   quantum=1e-6, base_error=0.0159)
    dg = diagnose(rec, believed, closed_loop=False)
    assert [f.effect for f in dg.findings] == ["deadband"]
    assert dg.findings[0].parameters["current"] == pytest.approx(0.0023, rel=0.3)
    dg.augmented_model()  # valid
    refused = [g for g in dg.trials if g["why"].startswith("not physical")]
    assert refused and all(not g["ok"] for g in refused)


def test_controller_hold_of_a_record_logged_off_its_updates():
    # logged at the update instants the force trails the commands by half a period; a
    # log whose interval is p/q controller periods catches them at q phases
    from lugre.diagnosis.residual import command_hold

    m = lugre.Model.paper().replace(controller={"type": "pid", "kp": 5e4, "ki": 5e5,
                                                "kd": 1500.0, "rate_hz": 5000.0})
    assert command_hold(m) == pytest.approx(1e-4)
    assert command_hold(m, 1e-3) == pytest.approx(1e-4)     # 1 kHz: every 5th update
    assert command_hold(m, 5e-4) == pytest.approx(0.5e-4)   # 2 kHz: 2.5 periods
    assert command_hold(m, 1e-4) == pytest.approx(0.5e-4)   # 10 kHz: twice per update


def test_lag_attenuation_is_the_lags_not_a_resonance():
    # a 64 Hz current lag on constant-speed feeds logged at 5 kHz: the selection's
    # timing column is a pure delay, so a damped resonance took up the lag's
    # attenuation and a mass read +0.3 kg speeding up and +2 kg braking. With every
    # term in its exact form the lag explains it all: no resonance, no "unexplained"
    from lugre.diagnosis.synth import case

    eff = {"effect": "current_lag", "bandwidth": 64.0}
    rec, _hold, believed, _ = case([eff], seed=20052, kind="feeds", duration=10.0,
                                   rate_hz=5000.0, current_noise=0.0093, quantum=1e-7,
                                   base_error=0.0106)
    dg = diagnose(rec, believed, closed_loop=False)
    assert [f.effect for f in dg.findings] == ["current_lag"]
    assert dg.findings[0].parameters["bandwidth"] == pytest.approx(64.0, rel=0.15)
    assert dg.unexplained is None
    # the base refit's floor held the lag's mismatch; the summary gives both floors
    assert re.search(r"Noise floor \S+ N rms before the findings, \S+ N after", dg.summary())


def test_resonance_profiled_again_with_the_delay_in():
    # a 28 Hz coupling beside a 1.05 ms delay, 30 s of point-to-point moves at 1 kHz:
    # chosen alone in the search's first step the resonance came out 32 Hz, damping
    # 0.1, and a 1.5 % drift was named beside it for what that left. Profiled again once
    # the delay is in: about 30 Hz, the delay within 10 %, no drift
    from lugre.diagnosis.synth import case

    effs = [{"effect": "delay", "seconds": 0.00105},
            {"effect": "resonance", "frequency": 27.98, "damping_ratio": 0.0576,
             "load_fraction": 0.68}]
    rec, _hold, believed, _ = case(effs, seed=22092, kind="p2p", duration=30.0,
                                   rate_hz=1000.0, current_noise=0.0113, quantum=1e-7,
                                   base_error=0.016)
    dg = diagnose(rec, believed, closed_loop=False)
    assert sorted(f.effect for f in dg.findings) == ["delay", "resonance"]
    res = next(f for f in dg.findings if f.effect == "resonance")
    assert res.parameters["frequency"] == pytest.approx(27.98, rel=0.1)
    delay = next(f for f in dg.findings if f.effect == "delay")
    assert delay.parameters["seconds"] == pytest.approx(0.00105, rel=0.1)


def test_two_effects_that_spoil_each_others_blocks_are_found_together():
    # a payload of 1.3 kg and a friction bump of 16 % on part of the stroke, 10 s of
    # sines: alone, each gained thousands of units on the held-out stretches but not
    # consistently (the other one's mismatch spoils its blocks: p = 0.08 and 0.05), and
    # the record was called unexplained. Tried together they pass, each adding to the
    # other alone.
    from lugre.diagnosis.synth import case

    c, w, g = -0.0584, 0.01897, 0.16
    xs = np.linspace(c - 3 * w, c + 3 * w, 25)
    bump = {"effect": "position_friction", "positions": xs.tolist(),
            "scale": (1.0 + g * np.exp(-0.5 * ((xs - c) / w) ** 2)).tolist()}
    payload = {"effect": "mass", "delta": 1.289}
    rec, hold, believed, _ = case([bump, payload], seed=21102, axis_seed=9176,
                                  kind="sines", duration=10.0, rate_hz=2000.0,
                                  current_noise=0.0077, quantum=5e-6, base_error=0.0173)
    dg = diagnose(rec, believed, holdout=hold, closed_loop=False)
    assert sorted(f.effect for f in dg.findings) == ["mass", "position_friction"]
    f = next(f for f in dg.findings if f.effect == "mass")
    assert f.parameters["delta"] == pytest.approx(1.289, rel=0.3)
    assert any("jointly with" in g["why"] for g in dg.trials)
    assert dg.fit["holdout_after"]["rms_force"] < 0.3 * dg.fit["holdout_before"]["rms_force"]


def test_verdict_says_when_the_refit_does_not_carry_over():
    # a record unlike its hold-out (an unstable stretch of a resonant axis made the base
    # refit move fc -100 %, sigma2 +800 %) made the held-out error 15 times larger while
    # the verdict read as usual; it must say not to use the augmented model
    from types import SimpleNamespace

    from lugre.diagnosis.evidence import verdict

    def dg(after):
        return SimpleNamespace(findings=[], base_moves=[], unexplained=None,
                               fit={"holdout_before": {"rms_force": 0.865},
                                    "holdout_after": {"rms_force": after}})

    worse, better = verdict(dg(12.9)), verdict(dg(0.5))
    assert "does not carry over" in worse and "+1391 %" in worse
    assert "does not carry over" not in better


def test_a_gain_the_readings_noise_makes_is_no_finding(monkeypatch):
    # a clean 17 kg axis, 0.1 um encoder, logged at 5 kHz on point-to-point moves and
    # diagnosed against the exact model that made it: a damped resonance smooths the
    # acceleration, twice-differentiated encoder noise included, and so "explains" part
    # of the noise in every held-out block. Without the SIMEX check it is named; with
    # it, the gain extrapolated to noise-free readings does not pass
    from lugre.diagnosis import joint
    from lugre.diagnosis.synth import case

    rec, _hold, _bel, truth = case([], seed=21019, axis_seed=3873, kind="p2p",
                                   duration=10.0, rate_hz=5000.0, current_noise=0.0235,
                                   quantum=1e-7, base_error=0.0)
    dg = diagnose(rec, truth, closed_loop=False)
    assert dg.findings == []
    dropped = [g for g in dg.trials if "SIMEX" in g["why"]]
    assert [g["effect"] for g in dropped] == ["resonance"]
    assert not dropped[0]["accepted"]
    assert "A resonance passed the held-out test but is not named" in dg.summary()
    monkeypatch.setattr(joint, "noise_made", lambda *a, **k: {})
    assert [f.effect for f in diagnose(rec, truth, closed_loop=False).findings] == [
        "resonance"]


def test_simex_surrogates_match_the_readings_noise():
    from lugre.diagnosis import residual as R
    from lugre.diagnosis.simex import surrogates
    from lugre.diagnosis.synth import case

    rec, _hold, _bel, truth = case([], seed=3, duration=6.0, current_noise=0.02,
                                   quantum=1e-6, base_error=0.0)
    sig = R.prepare(rec, truth)
    sur = surrogates(rec, truth, sig)
    assert len(sur) == 2
    for s in sur:  # same band, same rows; the force's added noise at the record's level
        assert s.cutoff_hz == sig.cutoff_hz and np.array_equal(s.mask, sig.mask)
    fs = 1.0 / rec.dt
    added = sur[0].force_raw - sig.force_raw
    level = R.hf_level(R.hampel(rec.force(truth))[0], fs)
    assert np.std(added) == pytest.approx(np.sqrt(level * 0.5 * fs), rel=0.05)
    # antithetic: the pair's additions cancel
    assert np.allclose(sur[0].force_raw + sur[1].force_raw, 2 * sig.force_raw)


def test_a_dead_band_is_the_same_where_the_drive_brakes():
    # a 27 % friction bump centred 76 mm behind the start of an 88 kg axis's
    # constant-speed feeds (which run from 0 to 711 mm: the record holds only its tail)
    # had been named a dead-band ("confined but overwhelming"): refitted where
    # the drive brakes the axis, that dead-band read 2.0 times its band against 0.56
    # overall. A dead-band is one size wherever the current is over it (the public
    # dead-band reads 1.05 braking and 1.03 overall and stays named: datasets tests)
    from lugre.diagnosis.synth import case

    c, w = -0.0761, 0.0312
    xs = np.linspace(c - 3 * w, c + 3 * w, 25)
    bump = {"effect": "position_friction", "positions": xs.tolist(),
            "scale": (1.0 + 0.2727 * np.exp(-0.5 * ((xs - c) / w) ** 2)).tolist()}
    rec, _hold, believed, _ = case([bump], seed=21062, axis_seed=7538, kind="feeds",
                                   duration=30.0, rate_hz=2000.0, current_noise=0.0186,
                                   quantum=1e-7, base_error=0.0082)
    dg = diagnose(rec, believed, closed_loop=False)
    assert "deadband" not in [f.effect for f in dg.findings]
    refused = [g for g in dg.trials
               if g["effect"] == "deadband" and "no one dead-band" in g["why"]]
    assert refused and not refused[0]["accepted"]


def test_simex_leaves_terms_that_do_not_smooth_a_reading():
    # a friction bump and a spring seen through a 5 um encoder at 1 kHz: the added
    # noise acts on the friction through its nonlinearity in the velocity (9887 units of
    # gain, 4383 "made" by the surrogate noise), not by correlation; checked by SIMEX the
    # two true findings were dropped. Only terms that smooth a reading are checked
    from lugre.diagnosis.synth import case

    c, w = 0.02884, 0.01531
    xs = np.linspace(c - 3 * w, c + 3 * w, 25)
    bump = {"effect": "position_friction", "positions": xs.tolist(),
            "scale": (1.0 + 0.2484 * np.exp(-0.5 * ((xs - c) / w) ** 2)).tolist()}
    spring = {"effect": "spring", "stiffness": 4.154, "x0": -0.00715}
    rec, _hold, believed, _ = case([bump, spring], seed=21100, axis_seed=419, kind="p2p",
                                   duration=10.0, rate_hz=1000.0, current_noise=0.00835,
                                   quantum=5e-6, base_error=0.0174)
    dg = diagnose(rec, believed, closed_loop=False)
    assert sorted(f.effect for f in dg.findings) == ["position_friction", "spring"]


def test_a_model_that_is_not_passive_is_warned_of_once_per_direction():
    # the search and the refits build hundreds of trial models from the one given; the
    # passivity warning is the given model's, once, not one per trial model
    import warnings

    from lugre.exceptions import PassivityWarning

    rec, believed, _ = concealed("cogging", duration=5.0)
    d = believed.to_dict()
    d["friction"]["sigma1"] = 50.0 * max(believed.passivity_bound())
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        diagnose(rec, d, closed_loop=False)
    told = [str(w.message) for w in caught if w.category is PassivityWarning]
    assert len(told) == 2 and "positive set" in told[0] and "negative set" in told[1]


@pytest.mark.parametrize("gain,p,expect", [
    (3.0, 0.0003, ("by too little to matter (a score gain of 3 against the 10 a finding "
                   "needs; gains in 10 of 10 stretches, p = 0.0003)")),
    (3.0, 0.3, ("does not improve the held-out fit consistently (gains in 6 of 10 "
                "stretches, p = 0.3)")),
    (40.0, 0.2, ("does not improve the held-out fit consistently (gains in 6 of 10 "
                 "stretches, p = 0.2)")),
])
def test_presliding_note_gives_the_reason_it_is_held(gain, p, expect):
    """The note on a held presliding pair says why: consistent but small gains are
    not called inconsistent."""
    from lugre.diagnosis.evidence import base_notes

    def entry(v):
        return {"before": v, "after": v, "change": 0.0, "tolerance": 0.1, "unit": "N",
                "status": "refitted"}

    base = {n: entry(28.0) for n in ("positive.fc", "negative.fc")}
    base["sigma1"] = dict(entry(31.6), status="not determined by this record (held)",
                          presliding_test={"gain": gain, "min_gain": 10.0, "alpha": 1e-3,
                                           "p": p, "positive": 10 if p < 1e-3 else 6,
                                           "blocks": 10, "free": False})
    notes = [n for n in base_notes(base, []) if n.startswith("sigma0 and sigma1")]
    assert len(notes) == 1 and expect in notes[0], notes


@pytest.mark.parametrize("effect", ["offset", "drag", "mass"])
def test_what_the_record_could_hide_is_what_the_search_misses(effect):
    # "a constant force under 0.29 N would not be seen in this record": the size is
    # judged by the search's own held-out test (and its practical size), so the same
    # record with the effect at 1.4 times that size names it, at 0.6 times it does not
    # (the earlier estimate, from the score gain alone, claimed sizes 2 to 5 times too
    # small: a 0.86 ms delay went unnamed where "under 0.46 ms" was said to hide)
    make = {"offset": lambda s: {"effect": "offset", "force": s},
            "drag": lambda s: {"effect": "drag", "coefficient": s},
            "mass": lambda s: {"effect": "mass", "delta": s}}[effect]
    rec, believed, _ = concealed(None, duration=12.0, seed=0)
    dg = diagnose(rec, believed, closed_loop=False)
    assert dg.findings == []
    limit = {h["effect"]: h["smallest"] for h in dg.could_not_reveal}[effect]
    assert limit is not None and limit > 0
    for k, seen in ((0.6, False), (1.4, True)):
        rec2, believed2, _ = concealed(make(k * limit), duration=12.0, seed=0)
        names = [f.effect for f in diagnose(rec2, believed2, closed_loop=False).findings]
        assert (effect in names) == seen, (k, limit, names)


def test_many_decisions_are_the_one_decision():
    # the detection sizes judge many sets of block gains at once: the same rule
    rng = np.random.default_rng(3)
    d = rng.normal(rng.uniform(-5, 40, (3000, 1)), rng.uniform(0, 60, (3000, 1)), (3000, 10))
    d[::7] = np.abs(d[::7])
    d[::11] = d[::11, :1]  # equal gains in every block (no spread)
    many = accept_many(d, d.sum(1), alpha=1e-3, min_gain=10.0)
    one = [accept(block_evidence(x), alpha=1e-3, min_gain=10.0)[0] for x in d]
    assert many.tolist() == one
    assert 0.1 < many.mean() < 0.9


def test_a_delay_between_slow_reversals_is_not_lost_motion():
    # constant-speed feeds with a 0.76 ms dead time and a 0.5 kg payload: between the
    # reversals the force hardly changes, and the recorded current's noise (11 mA) is
    # most of the lag's column there, which pulls the lag fitted there toward zero
    # (errors in variables: 0.25 ms). Read so, the delay was refused as lost motion;
    # corrected for that noise it is 0.87 +- 0.42 ms there, and the delay is named
    from lugre.diagnosis.synth import case

    effects = [{"effect": "delay", "seconds": 0.000765}, {"effect": "mass", "delta": 0.516}]
    rec, _hold, believed, _ = case(effects, seed=23096, axis_seed=6443, kind="feeds",
                                   duration=20.0, rate_hz=2000.0, current_noise=0.01094,
                                   quantum=1e-6, base_error=0.0173)
    dg = diagnose(rec, believed, closed_loop=False)
    names = {f.effect for f in dg.findings}
    assert "mass" in names and names & {"delay", "current_lag"}, dg.summary()
    lag = next(f for f in dg.findings if f.effect in ("delay", "current_lag"))
    assert lag.parameters["seconds"] == pytest.approx(0.000765, rel=0.3)


def test_a_model_with_its_timing_is_diagnosed_again():
    # the timing term is one of a kind (a delay and a lag at most once each): a model
    # that holds one is diagnosed with it kept as given
    rec, believed, _ = concealed({"effect": "current_lag", "bandwidth": 60.0}, duration=10.0)
    first = diagnose(rec, believed, closed_loop=False)
    assert {f.effect for f in first.findings} & {"delay", "current_lag"}
    again = diagnose(rec, first.augmented_model(), closed_loop=False)
    assert not {f.effect for f in again.findings} & {"delay", "current_lag"}
    assert any("already holds its timing" in n for n in again.notes)


def test_the_current_noise_in_the_force_rate_is_predicted():
    # the reversal check corrects the lag for the current's noise in its column (the
    # filtered force's rate of change): that noise's mean square, predicted from the
    # level above the band, matches what white current noise gives
    from lugre.diagnosis import residual as R
    from lugre.diagnosis.candidates.probe import rate_noise_power

    rng = np.random.default_rng(5)
    n = 20000
    t = np.arange(n) * 1e-3
    x = 0.05 * np.sin(2 * np.pi * 0.5 * t)
    for sd in (0.01, 0.05):
        rec = lugre.Recording(t=t, x=x, i=sd * rng.standard_normal(n))
        sig = R.prepare(rec, lugre.Model.paper())
        measured = float(np.mean(sig.dfm[sig.mask] ** 2))
        assert rate_noise_power(sig) == pytest.approx(measured, rel=0.1)


@pytest.mark.parametrize("setup", [
    # an 18 kg axis, point-to-point, logged at 5 kHz with a 0.1 um encoder: a damped
    # 88 Hz resonance went in as a minor correction, and a 0.1 ms delay, which gained
    # nothing without it, was named beside it
    {"seed": 24024, "axis_seed": 368, "kind": "p2p", "rate_hz": 5000.0,
     "current_noise": 0.00966, "quantum": 1e-7, "base_error": 0.0101},
    # a 14 kg axis on sines logged at 2 kHz, 5 um encoder, 34 mA of current noise: a
    # damped 27 Hz resonance (0.3, 73 % of the mass) was named
    {"seed": 24038, "axis_seed": 8846, "kind": "sines", "rate_hz": 2000.0,
     "current_noise": 0.0345, "quantum": 5e-6, "base_error": 0.0068},
])
def test_clean_records_of_an_unseen_set_name_nothing(setup):
    # stress seed 4, written and scored once at the end of session 9: 2 of its 20 clean
    # records named something. In both, noise like the record's own added to its
    # readings raised the resonance's gain by 60-65 % of itself (true resonances of the
    # generator and the public case: under 0.5 %); the linear extrapolation left the
    # rest standing. A term whose gain is mostly the readings' noise is not named, and
    # a term that passed only beside such a minor one is judged again without it
    from lugre.diagnosis.synth import case

    rec, _hold, believed, _ = case([], duration=20.0, **setup)
    dg = diagnose(rec, believed, closed_loop=False)
    assert dg.findings == [], dg.summary()
    assert any("SIMEX" in n for n in dg.notes)


def test_the_timing_alternative_reads_in_words():
    # a lag beside a delay it is not told apart from reads with its bandwidth and its
    # effective delay, not as a raw parameter dictionary
    rec, believed, _ = concealed({"effect": "current_lag", "bandwidth": 120.0}, duration=10.0)
    dg = diagnose(rec, believed, closed_loop=False)
    f = next(f for f in dg.findings if f.effect in ("delay", "current_lag"))
    assert f.alternatives  # (at 1 kHz the record does not tell a 120 Hz lag apart)
    line = next(ln for ln in dg.summary().splitlines() if "Equally well" in ln)
    assert re.search(r"bandwidth \d+ Hz, effective delay [\d.]+ ms", line), line


def test_an_offset_is_not_a_spring_with_its_rest_point_far_away():
    # a 3 N offset on 30 s of sines logged at 10 kHz was named a spring of -0.0175 N/m
    # with x0 at 171 m (on a 0.15 m stroke): the slope, 0.04 N rms beyond the offset,
    # was a small mass error the positions of the sines follow. What a term adds beyond
    # the simpler one it contains must be of practical size, as any finding
    rec, believed, _ = concealed("offset", duration=30.0, rate_hz=10000.0)
    dg = diagnose(rec, believed, closed_loop=False)
    assert [f.effect for f in dg.findings] == ["offset"], dg.summary()
    assert dg.findings[0].parameters["force"] == pytest.approx(3.0, rel=0.05)


def _with_effects(model, effects):
    d = model.to_dict()
    d["effects"] = effects
    return lugre.Model.from_dict(d)


def test_effects_the_record_contradicts_are_removed_from_the_model():
    # the model holds a cogging at the wrong pitch and a spring the axis lacks: both go,
    # and the record's own cogging (2.5 N at 30 mm) is found in their place (before,
    # "unexplained: resembles cogging, spring", and the augmented model kept both)
    rec, believed, _ = concealed("cogging", duration=8.0)
    given = _with_effects(believed, [
        {"effect": "cogging", "amplitude": 1.0, "pitch": 0.02, "phase": 0.0},
        {"effect": "spring", "stiffness": 5.0, "x0": 0.0}])
    dg = diagnose(rec, given, closed_loop=False)
    assert sorted(r["effect"] for r in dg.removed) == ["cogging", "spring"]
    assert all(r["p"] < 1e-3 or r["positive"] >= 3 for r in dg.removed)
    assert [f.effect for f in dg.findings] == ["cogging"]
    cog = dg.findings[0].parameters
    assert cog["pitch"] == pytest.approx(0.03, rel=0.01)
    assert cog["amplitude"] == pytest.approx(2.5, rel=0.05)
    kept = [e for e in dg.augmented.effects if e["effect"] in ("cogging", "spring")]
    assert len(kept) == 1 and kept[0]["pitch"] == pytest.approx(0.03, rel=0.01)
    assert dg.model == given  # the report's "before" is the model as given
    assert dg.fit["before"]["rms_force"] > 2.0 * dg.fit["after"]["rms_force"]
    assert dg.verdict.startswith("The model as given holds what this record contradicts")
    rep = dg.to_dict()
    assert [r["effect"] for r in rep["removed"]] == [r["effect"] for r in dg.removed]
    assert "Removed from the model: cogging" in dg.summary()


def test_a_finding_that_only_cancels_the_models_own_effect_removes_both():
    # a drift of 5 % the axis does not have: the search had found -4.8 % beside it. The
    # two together earn nothing on the held-out stretches, so the model's goes and no
    # drift is named. A payload of 1 kg where the record needs 0.29 kg (the believed
    # mass is light) is partly right: it is kept and the finding beside it says so
    rec, believed, _ = concealed("cogging", duration=8.0)
    plain = diagnose(rec, believed, closed_loop=False)
    need = sum(e["delta"] for e in plain.augmented.effects if e["effect"] == "mass")
    given = _with_effects(believed, [{"effect": "drift", "gain": 0.05, "time_constant": 2.0},
                                     {"effect": "mass", "delta": 1.0}])
    dg = diagnose(rec, given, closed_loop=False)
    assert [r["effect"] for r in dg.removed] == ["drift"]
    assert "found a drift of the opposite sense beside it" in dg.removed[0]["evidence"]
    assert not any(e["effect"] == "drift" for e in dg.augmented.effects)
    assert sorted(f.effect for f in dg.findings) == ["cogging", "mass"]
    total = sum(e["delta"] for e in dg.augmented.effects if e["effect"] == "mass")
    assert total == pytest.approx(need, abs=0.05)
    mass = next(f for f in dg.findings if f.effect == "mass")
    assert f"together delta {total:+.3g} kg" in mass.evidence


@pytest.mark.parametrize("scale", [1.0, 0.6])
def test_the_models_right_effects_are_kept(scale):
    # the record's own cogging, whole or at 0.6 of its size: kept (the shortfall is found
    # beside it); nothing the record supports is removed
    rec, believed, truth = concealed("cogging", duration=8.0)
    cog = dict(truth.effects[0])
    cog["amplitude"] *= scale
    dg = diagnose(rec, _with_effects(believed, [cog]), closed_loop=False)
    assert dg.removed == []
    assert dg.augmented.effects[0] == cog
    if scale == 1.0:
        assert dg.findings == []
    else:
        (f,) = dg.findings
        assert f.effect == "cogging"
        assert f.parameters["amplitude"] == pytest.approx(1.0, rel=0.1)


@pytest.mark.parametrize("given", [{"effect": "delay", "seconds": 0.0003},
                                   {"effect": "current_lag", "bandwidth": 400.0}])
def test_a_wrong_timing_in_the_model_is_replaced(given):
    # one of a kind: the timing term is not searched beside the model's own. A 0.3 ms
    # delay (or a 400 Hz lag) given where the drive has a 1 ms dead time was kept as
    # given and the rest went unexplained; searched again without it, the record's own
    # replaces it. The right one given is kept
    rec, believed, _ = concealed({"effect": "delay", "seconds": 0.001}, duration=10.0)
    dg = diagnose(rec, _with_effects(believed, [given]), closed_loop=False)
    assert [(r["effect"], r.get("replaced")) for r in dg.removed] == [(given["effect"], True)]
    (f,) = dg.findings
    assert f.effect == "delay"
    assert f.parameters["seconds"] == pytest.approx(0.001, rel=0.1)
    assert "does not match this record: searched again without it" in dg.verdict
    assert "Replaced in the model: " + given["effect"] in dg.summary()
    right = diagnose(rec, _with_effects(believed, [{"effect": "delay", "seconds": 0.001}]),
                     closed_loop=False)
    assert right.removed == [] and right.findings == []


def test_a_one_of_a_kind_effect_refined_by_little_is_kept():
    # a refinement is no contradiction: a model's delay within 5 % of what the record
    # prefers stays as given (a lightly damped resonance at 23.7 Hz preferred at 23.6 Hz
    # on a hold-out record had been "replaced"), one 25 % off is replaced
    from lugre.diagnosis.question import _differs

    assert not _differs({"effect": "resonance", "frequency": 23.7, "damping_ratio": 0.036,
                         "load_fraction": 0.48},
                        {"frequency": 23.6, "damping_ratio": 0.036, "load_fraction": 0.48})
    assert _differs({"effect": "current_lag", "bandwidth": 400.0},
                    {"seconds": 0.00096, "bandwidth": 166.0})
    assert not _differs({"effect": "current_lag", "bandwidth": 166.0},
                        {"seconds": 0.00096, "bandwidth": 170.0})
    rec, believed, _ = concealed({"effect": "delay", "seconds": 0.001}, duration=10.0)
    near = diagnose(rec, _with_effects(believed, [{"effect": "delay", "seconds": 0.00098}]),
                    closed_loop=False)
    assert near.removed == []
    far = diagnose(rec, _with_effects(believed, [{"effect": "delay", "seconds": 0.00075}]),
                   closed_loop=False)
    assert [r["effect"] for r in far.removed] == ["delay"]


def test_a_force_record_reads_its_dead_band_as_a_force():
    """A record that logged the motor force F (no current, K_F = 1): what it could hide
    of a dead-band is said in newtons, not as a current it never saw."""
    from lugre.diagnosis.synth import case

    rec, _hold, bel, _truth = case([], seed=7, duration=10.0)
    as_force = lugre.Recording(t=rec.t, x=rec.x, F=rec.i * bel.force_constant)
    model = bel.replace(axis={**bel.axis, "force_constant": 1.0})
    dg = diagnose(as_force, model, closed_loop=False)
    (db,) = [h for h in dg.could_not_reveal if h["effect"] == "deadband"]
    assert db["unit"] == "N" and " N of motor force" in db["text"] and "A" not in db["text"]
    dg_i = diagnose(rec, bel, closed_loop=False)
    (db_i,) = [h for h in dg_i.could_not_reveal if h["effect"] == "deadband"]
    assert db_i["unit"] == "A" and db_i["smallest"] * bel.force_constant == pytest.approx(
        db["smallest"], rel=0.05)


def test_a_record_that_barely_moves_back_is_refused_with_its_counts():
    """A move one way with a few samples of jitter the other way (a trapezoidal move of
    a robot joint, logged with repeated samples): one direction's friction cannot be
    read, so the fit and the diagnosis refuse it and say which direction and how much."""
    t = np.arange(4000) * 1e-3
    x = 0.2 * np.clip((t - 0.5) / 3.0, 0.0, 1.0)
    x[1000:1020:4] -= 2e-4  # a few jittery steps back
    rec = lugre.Recording(t=t, x=x, i=np.ones_like(t))
    with pytest.raises(DataError, match=r"one direction only: \d+ of its \d+ moving samples "
                                        r"go the negative way"):
        lugre.fit_model(rec, force_constant=25.0)
    with pytest.raises(DataError, match="record a move back"):
        diagnose(rec, lugre.Model.paper())


def test_a_candidate_the_base_cannot_simulate_is_skipped_not_fatal():
    """A fitted base with a bristle stiffness the record does not determine (a
    gravity-dominated joint's fit gave 1e12 N m/rad; here 1e18 N/m at 250 Hz) needs more
    substeps a sample than the load simulation behind a resonance takes: that candidate
    is skipped, the diagnosis runs."""
    from lugre.diagnosis.synth import case

    rec, _hold, believed, _ = case([], seed=31, kind="sines", duration=10.0, rate_hz=250.0)
    stiff = believed.with_friction(sigma0=1e18)
    with pytest.raises(lugre.ParameterError):
        lugre.load_coupling(rec.x, np.gradient(rec.x, rec.t), float(rec.t[1] - rec.t[0]),
                            stiff.replace(effects=[{"effect": "resonance", "frequency": 30.0,
                                                    "damping_ratio": 0.05,
                                                    "load_fraction": 0.5}]))
    dg = diagnose(rec, stiff, closed_loop=False)  # (raised that ParameterError before)
    assert "resonance" not in [f.effect for f in dg.findings]
