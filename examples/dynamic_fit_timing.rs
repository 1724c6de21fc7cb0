//! Times one closed-loop simulation and a full dynamic fit on a 4 s, 10 kHz stick-slip
//! record of the paper's axis (`cargo run --release --example dynamic_fit_timing`).

use lugre::estimate::{fit_dynamic, DynamicFitOptions};
use lugre::servo::{simulate, Drive, Model, SimOptions};
use std::time::Instant;

fn main() {
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
    let t0 = Instant::now();
    let reps = 20;
    let mut x = Vec::new();
    for _ in 0..reps {
        x = simulate(
            &m,
            &t,
            Drive::Position(&xr),
            &SimOptions::default(),
            &mut || true,
        )
        .expect("simulate")
        .x;
    }
    println!(
        "one simulation (40001 samples, 10 kHz): {:.2} ms",
        t0.elapsed().as_secs_f64() * 1e3 / reps as f64
    );
    let xq: Vec<f64> = x.iter().map(|v| (v / 1e-6).round() * 1e-6).collect();
    let mut start = m.clone();
    start.friction.sigma0 = 3e4;
    start.friction.sigma1 = 100.0;
    for _ in 0..3 {
        let t0 = Instant::now();
        let fit = fit_dynamic(&start, &t, &xr, &xq, &DynamicFitOptions::default()).expect("fit");
        println!(
            "fit: {:.3} s, {} simulations, {} IRLS iterations; sigma0 {:.2} ({:+.4} %), sigma1 {:.3} ({:+.2} %), CI sigma0 [{:.0}, {:.0}], CI sigma1 [{:.2}, {:.2}], identifiable {:?}",
            t0.elapsed().as_secs_f64(),
            fit.evaluations,
            fit.iterations,
            fit.sigma0,
            (fit.sigma0 / 1e5 - 1.0) * 100.0,
            fit.sigma1,
            (fit.sigma1 / 31.62 - 1.0) * 100.0,
            fit.ci_low[0],
            fit.ci_high[0],
            fit.ci_low[1],
            fit.ci_high[1],
            fit.identifiable
        );
    }
}
