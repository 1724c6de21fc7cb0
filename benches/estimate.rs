//! Speed of the identification: the static (Stribeck) fit on steady-state points, the
//! dynamic (sigma0, sigma1) fit on a closed-loop record, and the robust linear fit of
//! the inverse dynamics (IGG IRLS, beside plain least squares on the same design).
//!
//! The SciPy comparisons (`least_squares`, Nelder-Mead over the NumPy reference) and the
//! linear fit against its NumPy twin are in `benches/compare.py`.
//!
//! ```text
//! cargo bench --bench estimate -- --warm-up-time 1 --measurement-time 3
//! ```

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use lugre::estimate::{
    fit_dynamic, fit_static, irls_linear, irls_linear_grid, Design, DynamicFitOptions,
    LinearIrlsOptions, StaticFitOptions, Weighting,
};
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

/// `n` rows shaped like the inverse-dynamics fit (`benches/compare.py`'s
/// `linear_problem`): 5 base columns, 15 candidate hump pairs, noise and one row in ten
/// a gross error. Returns the base (column-major), the candidates and `y`.
fn linear_problem(n: usize) -> (Vec<f64>, Vec<Vec<f64>>, Vec<f64>) {
    let e = noise(2 * n);
    let t: Vec<f64> = (0..n).map(|k| 20.0 * k as f64 / (n - 1) as f64).collect();
    let v: Vec<f64> = t
        .iter()
        .zip(&e)
        .map(|(t, e)| 0.2 * (std::f64::consts::PI * t).sin() + 0.01 * e)
        .collect();
    let a: Vec<f64> = t
        .iter()
        .map(|t| 0.2 * std::f64::consts::PI * (std::f64::consts::PI * t).cos())
        .collect();
    let pos: Vec<f64> = v.iter().map(|v| if *v > 0.0 { 1.0 } else { 0.0 }).collect();
    let neg: Vec<f64> = v.iter().map(|v| if *v < 0.0 { 1.0 } else { 0.0 }).collect();
    let cols = [
        a,
        pos.clone(),
        pos.iter().zip(&v).map(|(p, v)| p * v).collect(),
        neg.iter().map(|x| -x).collect(),
        neg.iter().zip(&v).map(|(q, v)| q * v).collect(),
    ];
    let beta = [25.0, 20.0, 300.0, 21.0, 310.0];
    let extras: Vec<Vec<f64>> = (0..15)
        .map(|k| {
            let vs = 0.2 * 10f64.powf(-2.5 + 2.0 * k as f64 / 14.0);
            let hump: Vec<f64> = v.iter().map(|v| (-(v / vs) * (v / vs)).exp()).collect();
            let mut c: Vec<f64> = pos.iter().zip(&hump).map(|(p, h)| p * h).collect();
            c.extend(neg.iter().zip(&hump).map(|(q, h)| -q * h));
            c
        })
        .collect();
    let y: Vec<f64> = (0..n)
        .map(|i| {
            let f: f64 = cols.iter().zip(&beta).map(|(c, b)| c[i] * b).sum();
            let hump = 30.0 * extras[9][i] + 35.0 * extras[9][n + i];
            let gross = if i % 10 == 3 {
                10.0 * e[n + i].signum() + 5.0 * e[n + i]
            } else {
                0.0
            };
            f + hump + 0.3 * e[i] + gross
        })
        .collect();
    (cols.concat(), extras, y)
}

fn linear_fit(c: &mut Criterion) {
    let mut g = c.benchmark_group("irls_linear");
    g.sample_size(10);
    for &n in &[2000usize, 20_000] {
        let (x, extras, y) = linear_problem(n);
        let x7 = [x.clone(), extras[9].clone()].concat();
        let igg = LinearIrlsOptions::default();
        let ls = LinearIrlsOptions {
            weighting: Weighting::None,
            rounds: 1,
        };
        g.bench_with_input(BenchmarkId::new("igg_8_rounds", n), &n, |b, _| {
            b.iter(|| irls_linear(Design::new(&x7, n), &y, &igg).unwrap())
        });
        g.bench_with_input(BenchmarkId::new("least_squares", n), &n, |b, _| {
            b.iter(|| irls_linear(Design::new(&x7, n), &y, &ls).unwrap())
        });
        let cands: Vec<Design> = extras.iter().map(|e| Design::new(e, n)).collect();
        g.bench_with_input(BenchmarkId::new("grid_1_plus_15", n), &n, |b, _| {
            b.iter(|| irls_linear_grid(Design::new(&x, n), &cands, &y, &igg, 0.98).unwrap())
        });
    }
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default()
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(3));
    targets = static_fit, dynamic_fit, linear_fit
}
criterion_main!(benches);
