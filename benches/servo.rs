//! Speed of the servo + LuGre simulation, the LuGre force and batch simulation.
//!
//! Each group puts `lugre` beside the plain-loop limit: the same closed-loop step
//! written as one loop with nothing else (`plain_loop`, a transcription of
//! `benches/plain_loop.c`), so a regression shows as a ratio, not a guess. The NumPy
//! and SciPy comparisons are in `benches/compare.py`.
//!
//! ```text
//! cargo bench --bench servo -- --warm-up-time 1 --measurement-time 3
//! ```

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use lugre::friction::{friction_force_into, LugreParams, StaticSet};
use lugre::servo::{
    load_coupling, simulate, simulate_batch, CouplingOptions, Drive, Effect, Model, SimOptions,
};
use std::hint::black_box;
use std::time::Duration;

const RATE: f64 = 1e4;

/// Sample grid of `m` points over `steps` control periods and a sine reference
/// (5 mm, 25 periods over the run: stick at each reversal, slip in between).
fn grid(steps: usize, m: usize) -> (Vec<f64>, Vec<f64>) {
    let end = steps as f64 / RATE;
    let t: Vec<f64> = (0..m).map(|k| end * k as f64 / (m - 1) as f64).collect();
    let xr = t
        .iter()
        .map(|&s| 5e-3 * (2.0 * std::f64::consts::PI * 25.0 * s / end).sin())
        .collect();
    (t, xr)
}

/// The closed-loop step as one plain loop (see `benches/plain_loop.c`): PID on the
/// interpolated reference, exact bristle update, semi-implicit Euler, a sample of
/// (x, v, z, i, F, motor force) every `steps/(m-1)` steps.
fn plain_loop(p: &LugreParams, t: &[f64], xr_in: &[f64], steps: usize) -> Vec<f64> {
    let (mass, kf, kp, ki, kd) = (25.0, 25.0, 5e4, 5e5, 1500.0);
    let m = t.len();
    let dec = steps / (m - 1);
    let h = 1.0 / RATE;
    let mut out = Vec::with_capacity(6 * m);
    let (mut x, mut v, mut z, mut xi, mut xr_prev) = (xr_in[0], 0.0, 0.0, 0.0, 0.0);
    let mut j = 0;
    for n in 0..=steps {
        let tc = n as f64 / RATE;
        while j + 2 < m && t[j + 1] <= tc {
            j += 1;
        }
        let xr = if tc >= t[m - 1] {
            xr_in[m - 1]
        } else {
            xr_in[j] + (xr_in[j + 1] - xr_in[j]) * (tc - t[j]) / (t[j + 1] - t[j])
        };
        let xr_dot = if n == 0 { 0.0 } else { (xr - xr_prev) * RATE };
        xr_prev = xr;
        let e = xr - x;
        xi += e / RATE;
        let ic = (kp * e + ki * xi + kd * (xr_dot - v)) / kf;
        let (g, f, _) = p.eval(z, v, 1.0);
        if n % dec == 0 {
            out.extend_from_slice(&[x, v, z, ic, f, kf * ic]);
        }
        if n == steps {
            break;
        }
        let a = (kf * ic - f) / mass;
        z = p.advance_z(z, v, g, h);
        v += a * h;
        x += v * h;
    }
    out
}

fn paper_params() -> LugreParams {
    LugreParams::new(
        1e5,
        31.62,
        StaticSet::new(28.7, 60.2, 332.5, 0.01).unwrap(),
        StaticSet::new(28.5, 60.1, 333.0, 0.01).unwrap(),
    )
    .unwrap()
}

/// One trajectory, 1e4 to 1e7 control periods (one plant step each), output
/// decimated to 1001 samples; `full` records every step.
fn closed_loop(c: &mut Criterion) {
    let model = Model::paper();
    let p = paper_params();
    let opts = SimOptions::default();
    let mut g = c.benchmark_group("closed_loop_step");
    for &steps in &[10_000usize, 100_000, 1_000_000, 10_000_000] {
        if steps >= 1_000_000 {
            g.sample_size(10);
        }
        g.throughput(Throughput::Elements(steps as u64));
        let (t, xr) = grid(steps, 1001);
        g.bench_with_input(BenchmarkId::new("lugre", steps), &steps, |b, _| {
            b.iter(|| {
                simulate(&model, &t, Drive::Position(&xr), &opts, &mut || true)
                    .unwrap()
                    .x
            })
        });
        g.bench_with_input(BenchmarkId::new("plain_loop", steps), &steps, |b, &n| {
            b.iter(|| plain_loop(&p, black_box(&t), &xr, n))
        });
        if steps <= 1_000_000 {
            let (tf, xrf) = grid(steps, steps + 1);
            g.bench_with_input(
                BenchmarkId::new("lugre_full_output", steps),
                &steps,
                |b, _| {
                    b.iter(|| {
                        simulate(&model, &tf, Drive::Position(&xrf), &opts, &mut || true)
                            .unwrap()
                            .x
                    })
                },
            );
        }
    }
    g.finish();
}

/// `friction_force` over a sampled velocity (one exp() per sample in g, one in the
/// bristle update).
fn friction(c: &mut Criterion) {
    let p = paper_params();
    let mut g = c.benchmark_group("friction_force");
    for &n in &[1_000usize, 100_000, 1_000_000] {
        let v: Vec<f64> = (0..n)
            .map(|k| 0.05 * (2.0 * std::f64::consts::PI * k as f64 / n as f64).sin())
            .collect();
        let mut out = vec![0.0; n];
        g.throughput(Throughput::Elements(n as u64));
        g.bench_with_input(BenchmarkId::new("lugre", n), &n, |b, _| {
            b.iter(|| friction_force_into(&p, black_box(&v), 1e-4, 0.0, &mut out, None))
        });
    }
    g.finish();
}

/// `load_coupling` (the load behind a `resonance` driven by the motor motion) over
/// 20,000 samples at 10 kHz, the size of a diagnosis record.
fn coupling(c: &mut Criterion) {
    let mut m = Model::paper();
    m.effects.push(Effect::Resonance {
        frequency_hz: 22.0,
        damping_ratio: 0.04,
        load_fraction: 0.75,
    });
    let n = 20_000;
    let dt = 1e-4;
    let w = 2.0 * std::f64::consts::PI * 2.0;
    let x: Vec<f64> = (0..n).map(|k| 0.01 * (w * k as f64 * dt).sin()).collect();
    let v: Vec<f64> = (0..n)
        .map(|k| 0.01 * w * (w * k as f64 * dt).cos())
        .collect();
    let opts = CouplingOptions::default();
    let mut g = c.benchmark_group("load_coupling");
    g.throughput(Throughput::Elements(n as u64));
    g.bench_function(BenchmarkId::new("samples", n), |b| {
        b.iter(|| load_coupling(&m, black_box(&x), black_box(&v), dt, &opts).unwrap())
    });
    g.finish();
}

/// Eight models of one batch on 1 and on 2 worker threads.
fn batch(c: &mut Criterion) {
    let base = Model::paper();
    let models: Vec<Model> = (0..8)
        .map(|k| {
            let mut m = base.clone();
            m.friction.sigma0 = 5e4 + 1e4 * k as f64;
            m
        })
        .collect();
    let steps = 200_000;
    let (t, xr) = grid(steps, 1001);
    let opts = SimOptions::default();
    let mut g = c.benchmark_group("simulate_batch");
    g.sample_size(10);
    g.throughput(Throughput::Elements((steps * models.len()) as u64));
    for threads in [1usize, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        g.bench_with_input(BenchmarkId::new("threads", threads), &threads, |b, _| {
            b.iter(|| pool.install(|| simulate_batch(&models, &t, Drive::Position(&xr), &opts)))
        });
    }
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default()
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(3));
    targets = closed_loop, friction, coupling, batch
}
criterion_main!(benches);
