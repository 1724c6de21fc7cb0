//! Invariants of the LuGre model and its integrators.

use lugre::friction::{friction_force_into, rk4_z, LugreParams, StaticSet};
use proptest::prelude::*;

fn set() -> impl Strategy<Value = StaticSet<f64>> {
    (1.0f64..100.0, 0.0f64..2.0, 0.0f64..500.0, 1e-4f64..0.1)
        .prop_map(|(fc, r, s2, vs)| StaticSet::new(fc, fc * (1.0 + r), s2, vs).unwrap())
}

fn params() -> impl Strategy<Value = LugreParams<f64>> {
    (1e3f64..1e7, 0.0f64..1.0, set(), set()).prop_map(|(s0, r1, p, n)| {
        // sigma1 inside the passivity bound of both directions
        let bound = p
            .sigma1_passivity_bound()
            .min(n.sigma1_passivity_bound())
            .min(1e4);
        LugreParams::new(s0, r1 * bound, p, n).unwrap()
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    /// Once inside |z| <= max(fs)/sigma0, the exact update never leaves it, whatever
    /// the velocity and the step.
    #[test]
    fn bristle_state_stays_bounded(
        p in params(),
        vs in proptest::collection::vec(-1.0f64..1.0, 1..200),
        dt in 1e-6f64..1.0,
        z0 in -1.0f64..1.0,
    ) {
        let zmax = p.max_fs() / p.sigma0;
        let mut out = vec![0.0; vs.len()];
        let mut z = vec![0.0; vs.len()];
        let zend = friction_force_into(&p, &vs, dt, z0 * zmax, &mut out, Some(&mut z));
        for &zk in z.iter().chain(std::iter::once(&zend)) {
            prop_assert!(zk.abs() <= zmax * (1.0 + 1e-12));
        }
        prop_assert!(out.iter().all(|f| f.is_finite()));
    }

    /// At constant velocity the force settles on the Stribeck curve.
    #[test]
    fn steady_state_is_the_stribeck_curve(p in params(), v in -0.5f64..0.5) {
        prop_assume!(v.abs() > 1e-6);
        let g = p.set(v).g(v);
        // enough time for the bristles to settle: 40 time constants
        let tau = g / (p.sigma0 * v.abs());
        let n = 400;
        let vs = vec![v; n];
        let mut out = vec![0.0; n];
        friction_force_into(&p, &vs, tau / 10.0, 0.0, &mut out, None);
        let want = p.stribeck(v);
        prop_assert!((out[n - 1] - want).abs() <= 1e-9 * (1.0 + want.abs()),
            "got {} want {}", out[n - 1], want);
    }

    /// Friction never adds energy: a sliding mass with bristles, no other force, loses
    /// kinetic plus bristle energy (passive parameters).
    #[test]
    fn friction_never_adds_energy(p in params(), v0 in -0.5f64..0.5, m in 0.1f64..100.0) {
        let energy = |v: f64, z: f64| 0.5 * m * v * v + 0.5 * p.sigma0 * z * z;
        let (mut v, mut z) = (v0, 0.0);
        let e0 = energy(v, z);
        // RK4 on (v, z) with a step well inside every time constant
        let rate = p.sigma0 / p.positive.fc.min(p.negative.fc)
            + (p.sigma1 + p.positive.sigma2.max(p.negative.sigma2)) / m
            + (p.sigma0 / m).sqrt();
        let h = 0.05 / rate;
        let mut e_prev = e0;
        for _ in 0..2000 {
            let d = |v: f64, z: f64| {
                let (_, f, zdot) = p.eval(z, v, 1.0);
                (-f / m, zdot)
            };
            let k1 = d(v, z);
            let k2 = d(v + 0.5 * h * k1.0, z + 0.5 * h * k1.1);
            let k3 = d(v + 0.5 * h * k2.0, z + 0.5 * h * k2.1);
            let k4 = d(v + h * k3.0, z + h * k3.1);
            v += h / 6.0 * (k1.0 + 2.0 * k2.0 + 2.0 * k3.0 + k4.0);
            z += h / 6.0 * (k1.1 + 2.0 * k2.1 + 2.0 * k3.1 + k4.1);
            let e = energy(v, z);
            prop_assert!(e <= e_prev * (1.0 + 1e-9) + 1e-15, "energy rose from {} to {}", e_prev, e);
            e_prev = e;
        }
    }
}

/// RK4 on the bristle equation converges at fourth order; the exact update is exact.
#[test]
fn rk4_bristle_order_by_step_halving() {
    let s = StaticSet::new(28.7, 60.2, 332.5, 0.01).unwrap();
    let p = LugreParams::new(1e5, 31.62, s, s).unwrap();
    let v = 0.003;
    let t_end = 0.4; // two bristle time constants
    let exact = p.advance_z(0.0, v, s.g(v), t_end);
    let err = |n: usize| {
        let mut z = 0.0;
        for _ in 0..n {
            z = rk4_z(&p, z, v, t_end / n as f64);
        }
        (z - exact).abs()
    };
    let (e1, e2, e3) = (err(8), err(16), err(32));
    let (r1, r2) = (e1 / e2, e2 / e3);
    assert!(r1 > 13.0 && r1 < 19.0, "ratio {r1}");
    assert!(r2 > 13.0 && r2 < 19.0, "ratio {r2}");
    // the exact update in many small pieces equals one big step
    let mut z = 0.0;
    for _ in 0..1000 {
        z = p.advance_z(z, v, s.g(v), t_end / 1000.0);
    }
    assert!((z - exact).abs() < 1e-12 * exact.abs());
}
