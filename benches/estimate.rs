//! Speed of the identification: the static (Stribeck) fit on steady-state points and
//! the dynamic (sigma0, sigma1) fit on a closed-loop record.
//!
//! The SciPy comparisons (`least_squares`, Nelder-Mead over the NumPy reference) are in
//! `benches/compare.py`.
//!
//! ```text
//! cargo bench --bench estimate -- --warm-up-time 1 --measurement-time 3
//! ```

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use lugre::estimate::{fit_dynamic, fit_static, DynamicFitOptions, StaticFitOptions};
use lugre::friction::StaticSet;
use lugre::servo::{simulate, Drive, Model, SimOptions};
use std::time::Duration;

/// Deterministic noise in [-1, 1) (a linear congruential sequence).
fn noise(n: usize) -> Vec<f64> {
    let mut s: u64 = 0x2545_f491_4f6c_dd1d;
    (0..n)
        .map(|_| {
            s = s
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (s >> 11) as f64 / (1u64 << 52) as f64 - 1.0
        })
        .collect()
}

/// `n` points per direction, log-spaced speeds 0.2 mm/s to 0.4 m/s, 1 % noise and one
/// outlier in ten.
fn static_points(n: usize) -> (Vec<f64>, Vec<f64>) {
    let pos = StaticSet::new(28.7, 60.2, 332.5, 0.01).unwrap();
    let neg = StaticSet::new(28.5, 60.1, 333.0, 0.01).unwrap();
    let e = noise(2 * n);
    let mut v = Vec::with_capacity(2 * n);
    let mut f = Vec::with_capacity(2 * n);
    for k in 0..n {
        let s = 2e-4 * (2000.0f64).powf(k as f64 / (n - 1) as f64);
        for (sv, set, ek) in [(s, &pos, e[2 * k]), (-s, &neg, e[2 * k + 1])] {
            let outlier = if k % 10 == 3 { 1.3 } else { 1.0 };
            v.push(sv);
            f.push(set.stribeck(sv) * outlier * (1.0 + 0.01 * ek));
        }
    }
    (v, f)
}

fn static_fit(c: &mut Criterion) {
    let mut g = c.benchmark_group("fit_static");
    g.sample_size(10);
    for &n in &[20usize, 100, 1000] {
        let (v, f) = static_points(n);
        let opts = StaticFitOptions::default();
        g.bench_with_input(BenchmarkId::new("lugre", 2 * n), &n, |b, _| {
            b.iter(|| fit_static(&v, &f, &opts).unwrap())
        });
    }
    g.finish();
}

/// A 1 s closed-loop record at 10 kHz (ramp out and back at 1 mm/s, 1 um encoder).
fn dynamic_record() -> (Model, Vec<f64>, Vec<f64>, Vec<f64>) {
    let m = Model::paper();
    let t: Vec<f64> = (0..10_001).map(|k| k as f64 * 1e-4).collect();
    let xr: Vec<f64> = t
        .iter()
        .map(|&s| if s < 0.5 { 1e-3 * s } else { 1e-3 * (1.0 - s) })
        .collect();
    let r = simulate(
        &m,
        &t,
        Drive::Position(&xr),
        &SimOptions::default(),
        &mut || true,
    )
    .unwrap();
    let xq = r.x.iter().map(|x| (x / 1e-6).round() * 1e-6).collect();
    (m, t, xr, xq)
}

fn dynamic_fit(c: &mut Criterion) {
    let (m, t, xr, xq) = dynamic_record();
    let mut start = m.clone();
    start.friction.sigma0 = 3e4;
    start.friction.sigma1 = 100.0;
    let opts = DynamicFitOptions::default();
    let mut g = c.benchmark_group("fit_dynamic");
    g.sample_size(10);
    g.bench_function(BenchmarkId::new("lugre", t.len()), |b| {
        b.iter(|| fit_dynamic(&start, &t, &xr, &xq, &opts).unwrap())
    });
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default()
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(3));
    targets = static_fit, dynamic_fit
}
criterion_main!(benches);
