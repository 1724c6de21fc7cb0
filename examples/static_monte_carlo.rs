//! Monte Carlo comparison of the weight functions for the static (Stribeck) fit.
//!
//! 40 data sets with the paper's true parameters, 24 speeds per direction log-spaced
//! from 2e-4 to 0.4 m/s, 0.3 N Gaussian noise, 12 % of the points scaled by
//! `1 +- U(0.1, 0.4)` (gross errors). For each weighting: median and 95th percentile
//! of the worst relative parameter error (over the 8 static parameters) per data set.
//! `igg` and `tukey` are the defaults (IRLS, then least squares on the kept points with
//! the rejections re-checked); `-irls` rows stop after IRLS (`refit_kept: false`). The
//! oracle is least squares on the clean points only: the noise floor.
//!
//! Each point is a gross error with probability `share` (0.12 by default); `one-sided`
//! makes every gross error an increase (`1 + U(0.1, 0.4)`), the harder case for a
//! robust fit since the errors no longer cancel. The last column is the share of data
//! sets whose worst error is above 10 % (breakdown).
//!
//! `cargo run --release --example static_monte_carlo [n_sets] [seed] [share] [symmetric|one-sided]`

use lugre::estimate::{fit_static, quantile, StaticFit, StaticFitOptions, Weighting};
use lugre::friction::StaticSet;

/// SplitMix64: small, fast, deterministic.
struct Rng(u64);

impl Rng {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1).
    fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    /// Standard normal (Box-Muller).
    fn normal(&mut self) -> f64 {
        let u1 = 1.0 - self.uniform();
        let u2 = self.uniform();
        (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
    }
}

/// Largest relative error over the 8 static parameters.
fn worst_error(fit: &StaticFit, pos: &StaticSet, neg: &StaticSet) -> f64 {
    let mut m = 0.0f64;
    for (est, tr) in [(fit.positive.set, pos), (fit.negative.set, neg)] {
        for (a, b) in [
            (est.fc, tr.fc),
            (est.fs, tr.fs),
            (est.sigma2, tr.sigma2),
            (est.vs, tr.vs),
        ] {
            m = m.max(((a - b) / b).abs());
        }
    }
    m
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n_sets: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(40);
    let seed: u64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(2024);
    let share: f64 = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(0.12);
    let one_sided = args.get(4).is_some_and(|s| s == "one-sided");
    let pos = StaticSet::new(28.7, 60.2, 332.5, 0.01).expect("truth");
    let neg = StaticSet::new(28.5, 60.1, 333.0, 0.01).expect("truth");
    let speeds: Vec<f64> = (0..24)
        .map(|k| 2e-4 * (0.4f64 / 2e-4).powf(k as f64 / 23.0))
        .collect();
    let with = |weighting: Weighting, refit_kept: bool| StaticFitOptions {
        weighting,
        refit_kept,
        ..Default::default()
    };
    let schemes = [
        ("igg", with(Weighting::igg(), true)),
        ("igg-irls", with(Weighting::igg(), false)),
        ("huber", with(Weighting::huber(), true)),
        ("tukey", with(Weighting::tukey(), true)),
        ("tukey-irls", with(Weighting::tukey(), false)),
        ("none", with(Weighting::None, true)),
    ];
    let mut worst: Vec<Vec<f64>> = vec![Vec::new(); schemes.len() + 1];
    let mut outlier_recall = vec![0usize; schemes.len()];
    let mut fit_time = vec![0.0f64; schemes.len()];
    let mut false_reject = vec![0usize; schemes.len()];
    let mut evals = vec![0usize; schemes.len()];
    let mut n_outliers = 0usize;
    let mut rng = Rng(seed);
    let t0 = std::time::Instant::now();
    for _ in 0..n_sets {
        let mut v = Vec::new();
        let mut f = Vec::new();
        let mut is_out = Vec::new();
        for (sign, set) in [(1.0, &pos), (-1.0, &neg)] {
            for &s in &speeds {
                let vv = sign * s;
                let mut ff = set.stribeck(vv) + 0.3 * rng.normal();
                let out = rng.uniform() < share;
                if out {
                    let mag = 0.1 + 0.3 * rng.uniform();
                    let dir = if one_sided || rng.uniform() < 0.5 {
                        1.0
                    } else {
                        -1.0
                    };
                    ff *= 1.0 + dir * mag;
                }
                v.push(vv);
                f.push(ff);
                is_out.push(out);
            }
        }
        n_outliers += is_out.iter().filter(|o| **o).count();
        // oracle: least squares on the clean points only (the noise floor)
        let keep: Vec<usize> = (0..v.len()).filter(|&k| !is_out[k]).collect();
        let vc: Vec<f64> = keep.iter().map(|&k| v[k]).collect();
        let fc: Vec<f64> = keep.iter().map(|&k| f[k]).collect();
        let ls = StaticFitOptions {
            weighting: Weighting::None,
            ..Default::default()
        };
        let oracle = fit_static(&vc, &fc, &ls)
            .map(|fit| worst_error(&fit, &pos, &neg))
            .unwrap_or(f64::INFINITY);
        worst[schemes.len()].push(oracle);
        for (k, (name, opts)) in schemes.iter().enumerate() {
            let tf = std::time::Instant::now();
            let fit = fit_static(&v, &f, opts);
            fit_time[k] += tf.elapsed().as_secs_f64();
            let fit = match fit {
                Ok(fit) => fit,
                Err(e) => {
                    eprintln!("{name}: {e}");
                    worst[k].push(f64::INFINITY);
                    continue;
                }
            };
            worst[k].push(worst_error(&fit, &pos, &neg));
            evals[k] += fit.positive.evaluations + fit.negative.evaluations;
            for &r in &fit.rejected {
                if is_out[r] {
                    outlier_recall[k] += 1;
                } else {
                    false_reject[k] += 1;
                }
            }
        }
    }
    let above = |w: &[f64]| w.iter().filter(|e| **e > 0.1).count() as f64 / w.len() as f64;
    println!(
        "oracle (LS on clean points only): median {:.3} %, p95 {:.3} %, above 10 %: {:.1} %",
        100.0 * quantile(&worst[schemes.len()], 0.5),
        100.0 * quantile(&worst[schemes.len()], 0.95),
        100.0 * above(&worst[schemes.len()])
    );
    println!(
        "{n_sets} data sets (seed {seed}), gross errors {:.0} % {}, {} in all, {:.2} s",
        100.0 * share,
        if one_sided { "one-sided" } else { "symmetric" },
        n_outliers,
        t0.elapsed().as_secs_f64()
    );
    println!("weighting   median worst rel. err  p95 worst rel. err  outliers rejected  clean points rejected  ms per fit  evaluations per fit  above 10 %");
    for (k, (name, _)) in schemes.iter().enumerate() {
        println!(
            "{:<10}  {:>19.3} %  {:>16.3} %  {:>17}  {:>21}  {:>10.3}  {:>19.0}  {:>8.1} %",
            name,
            100.0 * quantile(&worst[k], 0.5),
            100.0 * quantile(&worst[k], 0.95),
            outlier_recall[k],
            false_reject[k],
            1e3 * fit_time[k] / n_sets as f64,
            evals[k] as f64 / n_sets as f64,
            100.0 * above(&worst[k])
        );
    }
}
