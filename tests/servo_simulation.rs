//! Servo simulation: convergence order, closed-loop behaviour, effects, bad input.

use lugre::servo::{simulate, simulate_batch, Drive, Integrator, Model, SimOptions};
use lugre::Error;

fn paper(effects: &str, controller: &str) -> Model {
    Model::from_json(&format!(
        r#"{{"axis": {{"mass": 25.0, "force_constant": 25.0}},
        "friction": {{"model": "lugre", "sigma0": 1e5, "sigma1": 31.62,
          "positive": {{"fc": 28.7, "fs": 60.2, "sigma2": 332.5, "vs": 0.01}},
          "negative": {{"fc": 28.5, "fs": 60.1, "sigma2": 333.0, "vs": 0.01}}}},
        "effects": [{effects}] {controller}}}"#
    ))
    .unwrap()
}

const PID: &str =
    r#", "controller": {"type": "pid", "kp": 5e4, "ki": 5e5, "kd": 1500, "rate_hz": 10000}"#;

fn grid(n: usize, dt: f64) -> Vec<f64> {
    (0..n).map(|k| k as f64 * dt).collect()
}

fn run(
    m: &Model,
    t: &[f64],
    d: Drive,
    integrator: Integrator,
    substeps: usize,
) -> lugre::servo::SimResult {
    let o = SimOptions {
        integrator,
        substeps,
        v0: 0.05,
        ..SimOptions::default()
    };
    simulate(m, t, d, &o, &mut || true).unwrap()
}

/// Halving the plant step: the exact-bristle splitting converges at first order, RK4
/// at fourth order (open loop, sliding without reversal so the right-hand side is smooth).
#[test]
fn integrator_order_by_step_halving() {
    let m = paper("", "");
    let t = grid(51, 2e-3);
    let i = vec![3.0; t.len()]; // 75 N pushes against ~45 N of friction
    let reference = run(&m, &t, Drive::Current(&i), Integrator::Rk4, 256);
    let err = |integ, sub| {
        let r = run(&m, &t, Drive::Current(&i), integ, sub);
        r.x.iter()
            .zip(&reference.x)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max)
    };
    let (e1, e2, e3) = (
        err(Integrator::Exact, 4),
        err(Integrator::Exact, 8),
        err(Integrator::Exact, 16),
    );
    for r in [e1 / e2, e2 / e3] {
        assert!(r > 1.7 && r < 2.3, "exact splitting ratio {r} (want ~2)");
    }
    let (e1, e2, e3) = (
        err(Integrator::Rk4, 1),
        err(Integrator::Rk4, 2),
        err(Integrator::Rk4, 4),
    );
    for r in [e1 / e2, e2 / e3] {
        assert!(r > 12.0 && r < 20.0, "rk4 ratio {r} (want ~16)");
    }
}

/// A slow ramp pulled through a soft position loop sticks and slips: the velocity drops
/// to zero again and again, while a fast ramp slides smoothly.
#[test]
fn slow_ramp_gives_stick_slip() {
    let soft = r#", "controller": {"type": "pid", "kp": 1e4, "ki": 0, "kd": 0, "rate_hz": 10000}"#;
    let m = paper("", soft);
    let t = grid(40_001, 1e-4);
    let rate = 0.01;
    let slow: Vec<f64> = t.iter().map(|&s| rate * s).collect();
    let r = simulate(
        &m,
        &t,
        Drive::Position(&slow),
        &SimOptions::default(),
        &mut || true,
    )
    .unwrap();
    let tail = &r.v[10_000..];
    let stops = tail
        .windows(2)
        .filter(|w| w[0] > 0.1 * rate && w[1] <= 0.1 * rate)
        .count();
    let vmax = tail.iter().cloned().fold(0.0, f64::max);
    assert!(stops >= 3, "stick-slip expected, {stops} stops");
    assert!(
        vmax > 2.0 * rate,
        "slip phases faster than the ramp, vmax {vmax}"
    );
    let fast: Vec<f64> = t.iter().map(|&s| 0.2 * s).collect();
    let r = simulate(
        &m,
        &t,
        Drive::Position(&fast),
        &SimOptions::default(),
        &mut || true,
    )
    .unwrap();
    assert!(
        r.v[20_000..].iter().all(|&v| v > 0.1),
        "smooth sliding at 0.2 m/s"
    );
}

/// Effects act as their formulas say: a constant offset is held by the integral action.
#[test]
fn offset_and_spring_are_held_by_the_integrator() {
    let t = grid(30_001, 1e-4);
    let hold = vec![0.0; t.len()];
    let m = paper(r#"{"effect": "offset", "force": 100.0}"#, PID);
    let r = simulate(
        &m,
        &t,
        Drive::Position(&hold),
        &SimOptions::default(),
        &mut || true,
    )
    .unwrap();
    let i_end = *r.i.last().unwrap();
    let f_end = *r.friction.last().unwrap();
    // motor force balances offset plus whatever the bristles still carry
    assert!(
        (25.0 * i_end - 100.0 - f_end).abs() < 1.0,
        "{i_end} {f_end}"
    );
    let m = paper(
        r#"{"effect": "spring", "stiffness": 2000.0, "x0": -0.05}"#,
        PID,
    );
    let r = simulate(
        &m,
        &t,
        Drive::Position(&hold),
        &SimOptions::default(),
        &mut || true,
    )
    .unwrap();
    let x_end = *r.x.last().unwrap();
    let want = 2000.0 * (x_end + 0.05) + r.friction.last().unwrap();
    assert!((25.0 * r.i.last().unwrap() - want).abs() < 1.0);
}

/// Mass, delay and lag change an open-loop response the expected way.
#[test]
fn mass_delay_and_lag() {
    let t = grid(101, 1e-3);
    let i = vec![4.0; t.len()];
    let o = SimOptions::default();
    let base = simulate(&paper("", ""), &t, Drive::Current(&i), &o, &mut || true).unwrap();
    let heavy = simulate(
        &paper(r#"{"effect": "mass", "delta": 25.0}"#, ""),
        &t,
        Drive::Current(&i),
        &o,
        &mut || true,
    )
    .unwrap();
    assert!(heavy.x[100] < 0.7 * base.x[100]);
    let late = simulate(
        &paper(r#"{"effect": "delay", "seconds": 0.01}"#, ""),
        &t,
        Drive::Current(&i),
        &o,
        &mut || true,
    )
    .unwrap();
    assert_eq!(late.x[10], 0.0); // no force before 10 ms
    assert!(late.force[11] > 99.0);
    let lag = simulate(
        &paper(r#"{"effect": "current_lag", "bandwidth": 50.0}"#, ""),
        &t,
        Drive::Current(&i),
        &o,
        &mut || true,
    )
    .unwrap();
    let tau = 1.0 / (2.0 * std::f64::consts::PI * 50.0);
    let want = 100.0 * (1.0 - (-0.005f64 / tau).exp());
    assert!(
        (lag.force[5] - want).abs() < 0.5,
        "{} vs {want}",
        lag.force[5]
    );
}

/// Batch results equal one-by-one results.
#[test]
fn batch_equals_serial() {
    let t = grid(2001, 1e-4);
    let xr: Vec<f64> = t.iter().map(|&s| 0.01 * s).collect();
    let models: Vec<Model> = (0..4)
        .map(|k| {
            let mut m = paper("", PID);
            m.friction.sigma0 *= 1.0 + 0.1 * k as f64;
            m
        })
        .collect();
    let o = SimOptions::default();
    let batch = simulate_batch(&models, &t, Drive::Position(&xr), &o);
    for (m, b) in models.iter().zip(batch) {
        let s = simulate(m, &t, Drive::Position(&xr), &o, &mut || true).unwrap();
        assert_eq!(s, b.unwrap());
    }
}

/// Bad input gives errors that name the problem, never a panic.
#[test]
fn bad_input_is_an_error() {
    let m = paper("", PID);
    let t = vec![0.0, 1e-4, 1e-4];
    let x = vec![0.0; 3];
    let e = simulate(
        &m,
        &t,
        Drive::Position(&x),
        &SimOptions::default(),
        &mut || true,
    )
    .unwrap_err();
    assert!(
        matches!(e, Error::Input { ref name, .. } if name == "t"),
        "{e}"
    );
    assert!(e.to_string().contains("strictly increasing"));
    let t = grid(3, 1e-4);
    let e = simulate(
        &m,
        &t,
        Drive::Position(&x[..2]),
        &SimOptions::default(),
        &mut || true,
    )
    .unwrap_err();
    assert!(
        e.to_string().contains("x_ref") && e.to_string().contains("same length"),
        "{e}"
    );
    let e = simulate(
        &m,
        &[],
        Drive::Position(&[]),
        &SimOptions::default(),
        &mut || true,
    )
    .unwrap_err();
    assert!(e.to_string().contains("empty"));
    let bad = vec![0.0, f64::NAN, 0.0];
    let e = simulate(
        &m,
        &t,
        Drive::Position(&bad),
        &SimOptions::default(),
        &mut || true,
    )
    .unwrap_err();
    assert!(e.to_string().contains("element 1"));
    let e = simulate(
        &paper("", ""),
        &t,
        Drive::Position(&x),
        &SimOptions::default(),
        &mut || true,
    )
    .unwrap_err();
    assert!(e.to_string().contains("controller"));
    let e = simulate(
        &m,
        &t,
        Drive::Speed(&x),
        &SimOptions::default(),
        &mut || true,
    )
    .unwrap_err();
    assert!(e.to_string().contains("x_ref"));
    // interruption
    let long = grid(200_000, 1e-4);
    let xr = vec![0.0; long.len()];
    let e = simulate(
        &m,
        &long,
        Drive::Position(&xr),
        &SimOptions::default(),
        &mut || false,
    )
    .unwrap_err();
    assert_eq!(e, Error::Interrupted);
}

fn sim(
    m: &Model,
    t: &[f64],
    d: Drive,
    integrator: Integrator,
    substeps: usize,
    v0: f64,
) -> lugre::servo::SimResult {
    let o = SimOptions {
        integrator,
        substeps,
        v0,
        ..SimOptions::default()
    };
    simulate(m, t, d, &o, &mut || true).unwrap()
}

fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

const RESONANCE: &str =
    r#"{"effect": "resonance", "frequency": 40.0, "damping_ratio": 0.05, "load_fraction": 0.6}"#;

/// Two-mass axis: halving the plant step shrinks the error at first order (exact
/// splitting: semi-implicit Euler on both bodies) and fourth order (RK4), in open loop
/// while both bodies slide forwards (smooth right-hand side).
#[test]
fn resonance_order_by_step_halving() {
    let effects = format!(
        r#"{RESONANCE}, {{"effect": "drag", "coefficient": 50.0}},
           {{"effect": "stribeck_shape", "exponent": 1.3}}"#
    );
    let m = paper(&effects, "");
    let t = grid(51, 2e-3);
    let i = vec![3.0; t.len()];
    let reference = sim(&m, &t, Drive::Current(&i), Integrator::Rk4, 512, 0.2);
    assert!(reference.v.iter().all(|&v| v > 0.05), "keeps sliding");
    let err = |integ, sub| {
        let r = sim(&m, &t, Drive::Current(&i), integ, sub, 0.2);
        max_abs_diff(&r.x, &reference.x)
    };
    let e: Vec<f64> = [4, 8, 16, 32]
        .iter()
        .map(|&s| err(Integrator::Exact, s))
        .collect();
    for w in e.windows(2) {
        let r = w[0] / w[1];
        assert!(
            r > 1.7 && r < 2.3,
            "exact ratio {r} (want ~2), errors {e:?}"
        );
    }
    let e: Vec<f64> = [2, 4, 8].iter().map(|&s| err(Integrator::Rk4, s)).collect();
    for w in e.windows(2) {
        let r = w[0] / w[1];
        assert!(
            r > 12.0 && r < 20.0,
            "rk4 ratio {r} (want ~16), errors {e:?}"
        );
    }
}

/// A mode too stiff for the plant step is refused, naming `substeps` and the fix.
#[test]
fn resonance_too_stiff_is_refused() {
    let stiff = r#"{"effect": "resonance", "frequency": 1200.0, "damping_ratio": 0.05, "load_fraction": 0.75}"#;
    let m = paper(stiff, PID);
    let t = grid(101, 1e-4);
    let xr = vec![0.0; t.len()];
    let o = SimOptions::default();
    let e = simulate(&m, &t, Drive::Position(&xr), &o, &mut || true).unwrap_err();
    let msg = e.to_string();
    assert!(
        matches!(e, Error::Parameter { ref name, .. } if name == "substeps"),
        "{msg}"
    );
    assert!(msg.contains("substeps >= 2"), "{msg}");
    // the suggested number of substeps runs
    let o = SimOptions { substeps: 2, ..o };
    let r = simulate(&m, &t, Drive::Position(&xr), &o, &mut || true).unwrap();
    assert!(r.x.iter().all(|x| x.is_finite()));
}

/// A command inside the dead band produces no force and no motion; beyond it the force
/// is `K_F*(|i| - band)`.
#[test]
fn deadband_inside_and_outside() {
    let m = paper(r#"{"effect": "deadband", "current": 0.5}"#, "");
    let t = grid(201, 1e-3);
    let inside: Vec<f64> = t
        .iter()
        .map(|&s| 0.45 * (2.0 * std::f64::consts::PI * 5.0 * s).sin())
        .collect();
    let r = sim(&m, &t, Drive::Current(&inside), Integrator::Exact, 1, 0.0);
    assert!(r.x.iter().all(|&x| x == 0.0) && r.force.iter().all(|&f| f == 0.0));
    assert_eq!(r.i, inside, "the recorded current is the command");
    let outside = vec![-4.0; t.len()];
    let r = sim(&m, &t, Drive::Current(&outside), Integrator::Exact, 1, 0.0);
    assert!(r.force.iter().all(|&f| f == 25.0 * (-3.5)));
    assert!(*r.x.last().unwrap() < -1e-3);
}

/// At constant speed the drag adds `c*v*|v|` to the Stribeck force the PID must supply.
#[test]
fn drag_steady_force() {
    let c = 120.0;
    let m = paper(&format!(r#"{{"effect": "drag", "coefficient": {c}}}"#), PID);
    let t = grid(20_001, 1e-4);
    for vr in [0.2, -0.3] {
        let xr: Vec<f64> = t.iter().map(|&s| vr * s).collect();
        let r = sim(&m, &t, Drive::Position(&xr), Integrator::Exact, 1, 0.0);
        let n = t.len();
        let f_motor = r.force[n - 2000..].iter().sum::<f64>() / 2000.0;
        let want = m.friction.stribeck(vr) + c * vr * vr.abs();
        assert!(
            (f_motor - want).abs() < 1e-3 * want.abs(),
            "v {vr}: motor force {f_motor} vs {want}"
        );
    }
}

/// The seed paper's axis in rotary units (the same numbers: inertia 25 kg m^2, torque
/// constant 25 N m/A, friction levels in N m), for `gravity`.
fn rotary(effects: &str, controller: &str) -> Model {
    let m = Model::from_json(&format!(
        r#"{{"axis": {{"kind": "rotary", "inertia": 25.0, "torque_constant": 25.0}},
        "friction": {{"sigma0": 1e5, "sigma1": 31.62,
          "positive": {{"fc": 28.7, "fs": 60.2, "sigma2": 332.5, "vs": 0.01}},
          "negative": {{"fc": 28.5, "fs": 60.1, "sigma2": 333.0, "vs": 0.01}}}},
        "effects": [{effects}] {controller}}}"#
    ))
    .unwrap();
    assert!(m.is_rotary());
    m
}

/// The amplifier's limit clips the force, after the dead band, and leaves the recorded
/// current (the command) as it was.
#[test]
fn current_limit_clips_the_force_not_the_record() {
    let m = paper(
        r#"{"effect": "current_limit", "current": 2.0}, {"effect": "deadband", "current": 0.5}"#,
        "",
    );
    let t = grid(401, 1e-3);
    let i: Vec<f64> = t
        .iter()
        .map(|&s| 4.0 * (2.0 * std::f64::consts::PI * 3.0 * s).sin())
        .collect();
    let r = sim(&m, &t, Drive::Current(&i), Integrator::Exact, 1, 0.0);
    assert_eq!(r.i, i, "the recorded current is the command");
    for (k, (&f, &c)) in r.force.iter().zip(&i).enumerate() {
        let db = if c > 0.5 {
            c - 0.5
        } else if c < -0.5 {
            c + 0.5
        } else {
            0.0
        };
        assert_eq!(f, 25.0 * db.clamp(-2.0, 2.0), "sample {k}");
    }
    assert_eq!(r.force.iter().fold(0.0f64, |a, f| a.max(f.abs())), 50.0);
    // closed loop: the controller asks for more than the limit, the force stays within
    let m = paper(r#"{"effect": "current_limit", "current": 3.0}"#, PID);
    let t = grid(6001, 1e-4);
    let xr: Vec<f64> = t
        .iter()
        .map(|&s| 0.02 * (2.0 * std::f64::consts::PI * 1.5 * s).sin())
        .collect();
    let r = sim(&m, &t, Drive::Position(&xr), Integrator::Exact, 1, 0.0);
    assert!(r.i.iter().any(|i| i.abs() > 3.5));
    assert!(r.force.iter().all(|f| f.abs() <= 75.0));
}

/// The motor force carries the ripple of the motor's position, scaled with the current.
#[test]
fn force_ripple_follows_the_position_and_the_current() {
    let (a, pitch, phase) = (0.05, 0.01, 0.7);
    let m = paper(
        &format!(
            r#"{{"effect": "force_ripple", "amplitude": {a}, "pitch": {pitch}, "phase": {phase}}}"#
        ),
        "",
    );
    let t = grid(301, 1e-3);
    for i0 in [3.0, -4.0] {
        let i = vec![i0; t.len()];
        let r = sim(&m, &t, Drive::Current(&i), Integrator::Exact, 1, 0.0);
        assert!(
            r.x.last().unwrap().abs() > 2.0 * pitch,
            "moves over pitches"
        );
        let w = 2.0 * std::f64::consts::PI / pitch;
        for k in 1..t.len() {
            let want = 25.0 * i0 * (1.0 + a * (w * r.x[k] + phase).sin());
            assert_eq!(r.force[k].to_bits(), want.to_bits(), "sample {k}");
        }
    }
}

/// A load-dependent friction raises the sliding friction by `coefficient*|F_m|`: at
/// constant speed the motor force is the Stribeck force over `1 - coefficient`.
#[test]
fn load_friction_steady_force() {
    let c = 0.15;
    let m = paper(
        &format!(r#"{{"effect": "load_friction", "coefficient": {c}}}"#),
        PID,
    );
    let t = grid(20_001, 1e-4);
    for vr in [0.2, -0.05] {
        let xr: Vec<f64> = t.iter().map(|&s| vr * s).collect();
        let r = sim(&m, &t, Drive::Position(&xr), Integrator::Exact, 1, 0.0);
        let n = t.len();
        let f_motor = r.force[n - 2000..].iter().sum::<f64>() / 2000.0;
        let want = m.friction.stribeck(vr) / (1.0 - c);
        assert!(
            (f_motor - want).abs() < 1e-3 * want.abs(),
            "v {vr}: motor force {f_motor} vs {want}"
        );
        // and the recorded friction is the raised one
        let f_fric = r.friction[n - 2000..].iter().sum::<f64>() / 2000.0;
        assert!(
            (f_fric - want).abs() < 1e-3 * want.abs(),
            "{f_fric} vs {want}"
        );
    }
}

/// A joint turning slowly under its load's weight: the motor torque is the friction
/// plus `torque*sin(x + phase)`.
#[test]
fn gravity_on_a_turning_joint() {
    let (tq, phase) = (40.0, 0.3);
    let m = rotary(
        &format!(r#"{{"effect": "gravity", "torque": {tq}, "phase": {phase}}}"#),
        PID,
    );
    let t = grid(40_001, 1e-4);
    let wr = 1.0; // rad/s, four radians
    let xr: Vec<f64> = t.iter().map(|&s| wr * s).collect();
    let r = sim(&m, &t, Drive::Position(&xr), Integrator::Exact, 1, 0.0);
    let mut worst = 0.0f64;
    for k in 5000..t.len() {
        let want = m.friction.stribeck(wr) + tq * (r.x[k] + phase).sin();
        worst = worst.max((r.force[k] - want).abs());
    }
    // (what is left is the inertia of the PID's tracking error)
    assert!(worst < 0.01 * tq, "{worst}");
}

/// The force residual of the inverse dynamics (`lugre::inverse`) of a noise-free record
/// simulated at the sampling rate (each sample a plant step: the acceleration is the
/// step's), with `model`; its rms over every sample but the last.
fn inverse_residual_rms(record: &lugre::servo::SimResult, t: &[f64], model: &Model) -> f64 {
    use lugre::inverse::{Lowpass, Record};
    let n = t.len();
    let dt = t[1] - t[0];
    let mut a: Vec<f64> = (0..n - 1)
        .map(|k| (record.v[k + 1] - record.v[k]) / dt)
        .collect();
    a.push(a[n - 2]);
    let fm: Vec<f64> = record
        .i
        .iter()
        .map(|i| model.axis.force_constant * i)
        .collect();
    let rec = Record::new(
        t.to_vec(),
        record.x.clone(),
        record.x.clone(),
        record.v.clone(),
        a,
        fm.clone(),
        fm,
        dt,
        Lowpass::identity(),
    )
    .unwrap();
    let r = rec.residual(model).unwrap();
    (r[..n - 1].iter().map(|x| x * x).sum::<f64>() / (n - 1) as f64).sqrt()
}

/// Each new effect simulated, then read back by the inverse dynamics: with the effect in
/// the model the residual is what the two discretisations leave (the bristles advanced
/// with the velocity held against the interval's mean), a small share of the residual
/// without it.
#[test]
fn inverse_dynamics_reads_back_the_simulated_effects() {
    let t = grid(8001, 1e-4);
    let xr: Vec<f64> = t
        .iter()
        .map(|&s| 0.02 * (2.0 * std::f64::consts::PI * 1.5 * s).sin())
        .collect();
    let turn: Vec<f64> = t.iter().map(|&s| 1.0 * s).collect();
    let cases = [
        (r#"{"effect": "load_friction", "coefficient": 0.15}"#, false),
        (
            r#"{"effect": "force_ripple", "amplitude": 0.05, "pitch": 0.01, "phase": 0.7}"#,
            false,
        ),
        (r#"{"effect": "current_limit", "current": 3.0}"#, false),
        (
            r#"{"effect": "gravity", "torque": 40.0, "phase": 0.3}"#,
            true,
        ),
        (
            r#"{"effect": "deadband", "current": 0.2}, {"effect": "current_limit", "current": 3.0},
               {"effect": "force_ripple", "amplitude": 0.05, "pitch": 0.01},
               {"effect": "load_friction", "coefficient": 0.1},
               {"effect": "cogging", "amplitude": 3.0, "pitch": 0.025}"#,
            false,
        ),
    ];
    for (effects, turning) in cases {
        let (truth, without, drive) = if turning {
            (rotary(effects, PID), rotary("", PID), &turn)
        } else {
            (paper(effects, PID), paper("", PID), &xr)
        };
        let r = sim(
            &truth,
            &t,
            Drive::Position(drive),
            Integrator::Exact,
            1,
            0.0,
        );
        let with = inverse_residual_rms(&r, &t, &truth);
        let plain = inverse_residual_rms(&r, &t, &without);
        // (measured: 0.02-0.04 N with the effect, 3.1-1471 N without)
        assert!(
            with < 0.1 && with < 0.02 * plain,
            "{effects}: {with} against {plain}"
        );
    }
}
