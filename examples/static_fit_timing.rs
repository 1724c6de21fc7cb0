//! Times the static (Stribeck) fit on many points: the paper's axis, `n` log-spaced
//! speeds per direction from 2e-4 to 0.4 m/s, 1 % multiplicative Gaussian noise, every
//! tenth point scaled by 1.3 (the data of `benches/compare.py --only static`, drawn
//! here by SplitMix64 instead of NumPy).
//!
//! `cargo run --release --example static_fit_timing [n_per_direction] [repeats]
//! [max_start_points]` (`all` for the starts on every point).

use lugre::estimate::{fit_static, StaticFitOptions};
use lugre::servo::Model;
use std::time::Instant;

/// SplitMix64 and Box-Muller: small, fast, deterministic.
struct Rng(u64);

impl Rng {
    fn uniform(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
    fn normal(&mut self) -> f64 {
        let u1 = 1.0 - self.uniform();
        let u2 = self.uniform();
        (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(10_000);
    let reps: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(3);
    let opts = StaticFitOptions {
        max_start_points: match args.get(3).map(String::as_str) {
            Some("all") => usize::MAX,
            Some(s) => s.parse().expect("max_start_points: a number or all"),
            None => StaticFitOptions::default().max_start_points,
        },
        ..StaticFitOptions::default()
    };
    let fr = Model::paper().friction;
    let mut rng = Rng(1);
    let s: Vec<f64> = (0..n)
        .map(|k| 2e-4 * 2000f64.powf(k as f64 / (n - 1) as f64))
        .collect();
    let v: Vec<f64> = s.iter().copied().chain(s.iter().map(|x| -x)).collect();
    let f: Vec<f64> = v
        .iter()
        .enumerate()
        .map(|(k, &vk)| {
            let set = if vk > 0.0 { fr.positive } else { fr.negative };
            let scale = if k % 10 == 0 { 1.3 } else { 1.0 };
            set.stribeck(vk) * (1.0 + 0.01 * rng.normal()) * scale
        })
        .collect();
    for _ in 0..reps.max(1) {
        let t0 = Instant::now();
        let fit = fit_static(&v, &f, &opts).expect("fit");
        let (p, m) = (fit.positive.set, fit.negative.set);
        println!(
            "{} points: {:.1} ms; fs {:.5} / {:.5}, fc {:.5} / {:.5}, vs {:.7} / {:.7}, {} rejected",
            v.len(),
            t0.elapsed().as_secs_f64() * 1e3,
            p.fs,
            m.fs,
            p.fc,
            m.fc,
            p.vs,
            m.vs,
            fit.rejected.len()
        );
    }
}
