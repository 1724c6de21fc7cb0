//! Dynamic (sigma0, sigma1) identification on a simulated stick-slip record.

use lugre::estimate::{fit_dynamic, DynamicFitOptions};
use lugre::servo::{simulate, Drive, Model, SimOptions};
use std::time::Instant;

/// 4 s at 10 kHz: a slow ramp out and back (1 mm/s), position quantised to 1 um.
fn record() -> (Model, Vec<f64>, Vec<f64>, Vec<f64>) {
    let m = Model::paper();
    let t: Vec<f64> = (0..40001).map(|k| k as f64 * 1e-4).collect();
    let xr: Vec<f64> = t
        .iter()
        .map(|&s| {
            if s < 2.0 {
                1e-3 * s
            } else {
                2e-3 - 1e-3 * (s - 2.0)
            }
        })
        .collect();
    let r = simulate(
        &m,
        &t,
        Drive::Position(&xr),
        &SimOptions::default(),
        &mut || true,
    )
    .unwrap();
    let xq: Vec<f64> = r.x.iter().map(|x| (x / 1e-6).round() * 1e-6).collect();
    (m, t, xr, xq)
}

#[test]
fn stick_slip_record_recovers_sigma0() {
    let (m, t, xr, xq) = record();
    // the record does stick and slip: the velocity returns to ~0 repeatedly
    let mut start = m.clone();
    start.friction.sigma0 = 3e4;
    start.friction.sigma1 = 100.0;
    let t0 = Instant::now();
    let fit = fit_dynamic(&start, &t, &xr, &xq, &DynamicFitOptions::default()).unwrap();
    let dt = t0.elapsed();
    let e0 = fit.sigma0 / 1e5 - 1.0;
    let e1 = fit.sigma1 / 31.62 - 1.0;
    eprintln!(
        "sigma0 {:.2} (err {:.4} %), sigma1 {:.3} (err {:.2} %), CI0 [{:.1}, {:.1}], CI1 [{:.2}, {:.2}]",
        fit.sigma0,
        e0 * 100.0,
        fit.sigma1,
        e1 * 100.0,
        fit.ci_low[0],
        fit.ci_high[0],
        fit.ci_low[1],
        fit.ci_high[1]
    );
    eprintln!(
        "identifiable {:?}, corr {:.3}, rho {:.3}, rms {:.3e}, iterations {}, simulations {}, time {:?}",
        fit.identifiable,
        fit.correlation,
        fit.residual_autocorrelation,
        fit.rms_error,
        fit.iterations,
        fit.evaluations,
        dt
    );
    for n in &fit.notes {
        eprintln!("  note: {n}");
    }
    assert!(e0.abs() < 0.02, "sigma0 {}", fit.sigma0);
    assert!(fit.identifiable[0]);
    assert!(fit.ci_low[0] <= 1e5 && 1e5 <= fit.ci_high[0]);
    assert!(fit.notes.iter().any(|n| n.contains("sigma1")));
}

#[test]
fn bad_inputs() {
    let (m, t, xr, xq) = record();
    let o = DynamicFitOptions::default();
    assert!(fit_dynamic(&m, &t, &xr[..10], &xq, &o).is_err());
    let flat = vec![0.0; t.len()];
    let e = fit_dynamic(&m, &t, &xr, &flat, &o).unwrap_err();
    assert!(matches!(e, lugre::Error::Data(_)), "{e}");
    let mut nc = m.clone();
    nc.controller = None;
    assert!(fit_dynamic(&nc, &t, &xr, &xq, &o).is_err());
    let bad = DynamicFitOptions {
        sigma0_start: Some(-1.0),
        ..o
    };
    assert!(fit_dynamic(&m, &t, &xr, &xq, &bad).is_err());
}

#[test]
fn gross_errors_rejected_and_both_coordinate_choices_agree() {
    let (m, t, xr, mut xq) = record();
    // 1 % of the samples hit by encoder glitches of +-20 to 50 um
    let mut state = 12345u64;
    let mut uniform = || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut glitches = Vec::new();
    for (k, x) in xq.iter_mut().enumerate() {
        if uniform() < 0.01 {
            let sign = if uniform() < 0.5 { -1.0 } else { 1.0 };
            *x += sign * (20e-6 + 30e-6 * uniform());
            glitches.push(k);
        }
    }
    let mut start = m.clone();
    start.friction.sigma0 = 3e4;
    start.friction.sigma1 = 100.0;
    let fast = fit_dynamic(&start, &t, &xr, &xq, &DynamicFitOptions::default()).unwrap();
    let plain = fit_dynamic(
        &start,
        &t,
        &xr,
        &xq,
        &DynamicFitOptions {
            rescale: false,
            ..Default::default()
        },
    )
    .unwrap();
    for f in [&fast, &plain] {
        eprintln!(
            "sigma0 {:.2} sigma1 {:.3} CI1 [{:.2}, {:.2}] simulations {} iterations {}",
            f.sigma0, f.sigma1, f.ci_low[1], f.ci_high[1], f.evaluations, f.iterations
        );
        assert!((f.sigma0 / 1e5 - 1.0).abs() < 0.01, "sigma0 {}", f.sigma0);
        let rejected = glitches.iter().filter(|&&k| f.weights[k] == 0.0).count();
        assert!(
            rejected * 10 >= glitches.len() * 9,
            "{rejected} of {}",
            glitches.len()
        );
    }
    // the two coordinate choices agree well inside the intervals
    let se0 = fast.std_err[0];
    assert!((fast.sigma0 - plain.sigma0).abs() < 0.5 * se0);
    assert!((fast.sigma1 - plain.sigma1).abs() < 0.5 * fast.std_err[1]);
}
