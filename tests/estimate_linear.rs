//! Robust linear least squares by IRLS (`estimate::linear`): gross errors rejected where
//! least squares is pulled, the grid's choice, and errors instead of panics.

use lugre::estimate::{irls_linear, irls_linear_grid, Design, LinearIrlsOptions, Weighting};
use lugre::Error;
use proptest::prelude::*;

/// Deterministic uniform numbers in [0, 1) (a linear congruential sequence).
fn uniform(n: usize, seed: u64) -> Vec<f64> {
    let mut s = seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1;
    (0..n)
        .map(|_| {
            s = s
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        })
        .collect()
}

/// Approximately Gaussian noise (sum of four uniforms, unit variance).
fn noise(n: usize, seed: u64) -> Vec<f64> {
    let u = uniform(4 * n, seed);
    u.chunks(4)
        .map(|c| (c.iter().sum::<f64>() - 2.0) * 3.0f64.sqrt())
        .collect()
}

/// `y = 2 - t + 0.5 t^2 + 0.05 noise` on `t` in [-1, 1], columns `1, t, t^2`, and 15 %
/// of the rows raised by 1 to 3 (20 to 60 noise levels, all upwards).
fn planted(n: usize) -> (Vec<f64>, Vec<f64>, Vec<bool>) {
    let t: Vec<f64> = (0..n)
        .map(|k| -1.0 + 2.0 * k as f64 / (n - 1) as f64)
        .collect();
    let e = noise(n, 11);
    let u = uniform(2 * n, 12);
    let mut y = Vec::with_capacity(n);
    let mut bad = Vec::with_capacity(n);
    for k in 0..n {
        let gross = u[2 * k] < 0.15;
        let mut v = 2.0 - t[k] + 0.5 * t[k] * t[k] + 0.05 * e[k];
        if gross {
            v += 1.0 + 2.0 * u[2 * k + 1];
        }
        y.push(v);
        bad.push(gross);
    }
    let x = [vec![1.0; n], t.clone(), t.iter().map(|t| t * t).collect()].concat();
    (x, y, bad)
}

#[test]
fn igg_rejects_planted_gross_errors_that_pull_least_squares() {
    let n = 2000;
    let (x, y, bad) = planted(n);
    let truth = [2.0, -1.0, 0.5];
    let robust = irls_linear(Design::new(&x, n), &y, &LinearIrlsOptions::default()).unwrap();
    let plain = irls_linear(
        Design::new(&x, n),
        &y,
        &LinearIrlsOptions {
            weighting: Weighting::None,
            rounds: 1,
        },
    )
    .unwrap();
    // standard errors of least squares on clean data: about 0.002 to 0.006 here
    for (j, b) in truth.iter().enumerate() {
        assert!((robust.coef[j] - b).abs() < 0.02, "{:?}", robust.coef);
    }
    assert!((plain.coef[0] - truth[0]).abs() > 0.2, "{:?}", plain.coef);
    for (w, gross) in robust.weights.iter().zip(&bad) {
        if *gross {
            assert_eq!(*w, 0.0);
        }
    }
    let kept_clean = robust
        .weights
        .iter()
        .zip(&bad)
        .filter(|(w, g)| !**g && **w > 0.0)
        .count();
    let clean = bad.iter().filter(|g| !**g).count();
    assert!(kept_clean as f64 > 0.97 * clean as f64);
}

#[test]
fn grid_chooses_the_hump_that_is_there() {
    let n = 3000;
    let v: Vec<f64> = (0..n)
        .map(|k| -0.2 + 0.4 * k as f64 / (n - 1) as f64)
        .collect();
    let sign = |v: f64| {
        if v > 0.0 {
            1.0
        } else if v < 0.0 {
            -1.0
        } else {
            0.0
        }
    };
    let hump = |vs: f64| -> Vec<f64> {
        v.iter()
            .map(|v| sign(*v) * (-(v / vs) * (v / vs)).exp())
            .collect()
    };
    let x = [v.iter().map(|v| sign(*v)).collect::<Vec<_>>(), v.clone()].concat();
    let h = [hump(0.002), hump(0.02), hump(0.1)];
    let e = noise(n, 3);
    let y: Vec<f64> = (0..n)
        .map(|k| 20.0 * sign(v[k]) + 300.0 * v[k] + 8.0 * h[1][k] + 0.3 * e[k])
        .collect();
    let extras: Vec<Design> = h.iter().map(|c| Design::new(c, n)).collect();
    let g = irls_linear_grid(
        Design::new(&x, n),
        &extras,
        &y,
        &LinearIrlsOptions::default(),
        0.98,
    )
    .unwrap();
    assert_eq!(g.chosen, Some(1));
    assert!((g.fit.coef[2] - 8.0).abs() < 0.3, "{:?}", g.fit.coef);
    assert_eq!(g.sse.len(), 3);
    assert!(g.fit.sse < 0.98 * g.base_sse);
}

/// The argument an error names (panics on success or another kind of error).
fn named<T>(r: lugre::Result<T>) -> String {
    match r {
        Err(Error::Input { name, .. }) | Err(Error::Parameter { name, .. }) => name,
        Err(e) => panic!("unexpected {e}"),
        Ok(_) => panic!("accepted"),
    }
}

#[test]
fn bad_input_is_an_error_naming_the_argument() {
    let (x, y, _) = planted(20);
    let o = LinearIrlsOptions::default();
    let mut nan = x.clone();
    nan[25] = f64::NAN;
    assert_eq!(named(irls_linear(Design::new(&nan, 20), &y, &o)), "X");
    let mut yinf = y.clone();
    yinf[3] = f64::INFINITY;
    assert_eq!(named(irls_linear(Design::new(&x, 20), &yinf, &o)), "y");
    assert_eq!(named(irls_linear(Design::new(&x, 20), &y[1..], &o)), "y");
    let tukey0 = LinearIrlsOptions {
        weighting: Weighting::Tukey { c: 0.0 },
        rounds: 8,
    };
    assert_eq!(
        named(irls_linear(Design::new(&x, 20), &y, &tukey0)),
        "weighting.c"
    );
    let short = vec![1.0; 19];
    assert_eq!(
        named(irls_linear_grid(
            Design::new(&x, 20),
            &[Design::new(&short, 19)],
            &y,
            &o,
            0.98
        )),
        "extras[0]"
    );
    assert_eq!(
        named(irls_linear_grid(Design::new(&x, 20), &[], &y, &o, 0.0)),
        "ratio"
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Any shape and any values, NaN and infinities included: a result or an error,
    /// never a panic; a result is consistent (weights from its residuals at its scale,
    /// residuals `y - X b`, `sse = sum w e^2`).
    #[test]
    fn never_panics_and_results_are_consistent(
        rows in 0usize..30, cols in 0usize..6, len_off in 0usize..2, seed in 0u64..1000,
        special in prop::sample::select(vec![0.0, f64::NAN, f64::INFINITY, 1e200, 0.5]),
        weighting in prop::sample::select(vec!["igg", "huber", "tukey", "none"]),
    ) {
        let mut x: Vec<f64> = noise(rows * cols, seed);
        if special != 0.5 && !x.is_empty() {
            let k = seed as usize % x.len();
            x[k] = special;
        }
        let y: Vec<f64> = noise(rows + len_off, seed + 1);
        let opts = LinearIrlsOptions {
            weighting: Weighting::from_name(weighting).unwrap(),
            rounds: 1 + seed as usize % 8,
        };
        if let Ok(f) = irls_linear(Design::new(&x, rows), &y, &opts) {
            prop_assert_eq!(f.coef.len(), cols);
            let w = opts.weighting.weights(&f.residuals, f.scale);
            prop_assert_eq!(&w, &f.weights);
            let mut sse = 0.0;
            for i in 0..rows {
                let mut fit = 0.0;
                for j in 0..cols {
                    fit += x[j * rows + i] * f.coef[j];
                }
                let tol = 1e-9 * (1.0 + y[i].abs() + fit.abs());
                prop_assert!((y[i] - fit - f.residuals[i]).abs() <= tol);
                prop_assert!((0.0..=1.0).contains(&f.weights[i]));
                sse += f.weights[i] * f.residuals[i] * f.residuals[i];
            }
            prop_assert!((sse - f.sse).abs() <= 1e-12 * (1.0 + sse));
        }
    }
}
