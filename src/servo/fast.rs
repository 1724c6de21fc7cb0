//! LuGre friction for the long loops of the load simulation ([`super::load_coupling`])
//! and of the inverse dynamics (`crate::inverse`): the operations of
//! [`LugreParams::eval`], [`LugreParams::eval_shaped`] and [`LugreParams::advance_z`]
//! in the same order, with the Stribeck exponential skipped where it cannot change
//! `g(v)`. The results are bit-identical to those of [`LugreParams`], and with the
//! levels raised by a `load_friction` to those of `effects::eval_loaded`.
//!
//! `g(v) = fc + (fs - fc)*exp(-p)`, `p = |v/vs|^n`: when `(fs - fc)*exp(-p)` is below
//! `fc*2^-54` (less than half a unit in the last place of `fc`), the sum rounds to `fc`
//! exactly. That holds for `p > ln((fs - fc)/fc) + 60*ln(2)` (6 bits of margin for
//! the rounding of `exp`, the product and the threshold itself): at the paper's values,
//! speeds above about 6.7 `vs`, most of the samples of a moving axis. With both levels
//! raised by `level >= 0`, `(fc + level) + (fs - fc)*exp(-p)` rounds to `fc + level` under
//! the same threshold (a larger sum has a larger unit in the last place).

use crate::friction::{LugreParams, StaticSet};

/// One direction's static set, with the threshold of `p` above which `g = fc`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Curve {
    fc: f64,
    dfs: f64,
    vs: f64,
    s2: f64,
    /// Exponent 2: threshold of `p = (v/vs)^2`; other exponents: threshold of `|v/vs|`.
    skip: f64,
}

impl Curve {
    fn new(s: &StaticSet<f64>, exponent: Option<f64>) -> Curve {
        let dfs = s.fs - s.fc;
        // -inf when fs == fc: g = fc everywhere
        let p = (dfs / s.fc).ln() + 60.0 * core::f64::consts::LN_2;
        let skip = match exponent {
            None => p,
            // |v/vs| > (p + 1)^(1/n) gives |v/vs|^n > p whatever the rounding of powf
            Some(e) => (p.max(0.0) + 1.0).powf(1.0 / e),
        };
        Curve {
            fc: s.fc,
            dfs,
            vs: s.vs,
            s2: s.sigma2,
            skip,
        }
    }
}

/// The Stribeck curve's shape, chosen once per loop (monomorphised).
pub(crate) trait Shape: Copy + Send + Sync {
    /// `g(v)` of the set `c` (unscaled), as [`StaticSet::g`] or [`StaticSet::g_shaped`].
    fn g(self, c: &Curve, v: f64) -> f64;

    /// `g(v)` with both levels raised by `level >= 0` [N], as `effects::g_loaded`:
    /// `(fc + level) + (fs - fc)*exp(-p)`.
    fn g_level(self, c: &Curve, v: f64, level: f64) -> f64;
}

/// Exponent 2 ([`StaticSet::g`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Square;

impl Shape for Square {
    #[inline(always)]
    fn g(self, c: &Curve, v: f64) -> f64 {
        let r = v / c.vs;
        let p = r * r;
        if p > c.skip {
            c.fc
        } else {
            c.fc + c.dfs * (-p).exp()
        }
    }

    #[inline(always)]
    fn g_level(self, c: &Curve, v: f64, level: f64) -> f64 {
        let r = v / c.vs;
        let p = r * r;
        if p > c.skip {
            c.fc + level
        } else {
            (c.fc + level) + c.dfs * (-p).exp()
        }
    }
}

/// Another exponent ([`StaticSet::g_shaped`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Power(pub(crate) f64);

impl Shape for Power {
    #[inline(always)]
    fn g(self, c: &Curve, v: f64) -> f64 {
        let r = (v / c.vs).abs();
        if r > c.skip {
            c.fc
        } else {
            c.fc + c.dfs * (-(r.powf(self.0))).exp()
        }
    }

    #[inline(always)]
    fn g_level(self, c: &Curve, v: f64, level: f64) -> f64 {
        let r = (v / c.vs).abs();
        if r > c.skip {
            c.fc + level
        } else {
            (c.fc + level) + c.dfs * (-(r.powf(self.0))).exp()
        }
    }
}

/// LuGre parameters prepared for a loop.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Fast {
    s0: f64,
    s1: f64,
    pos: Curve,
    neg: Curve,
}

impl Fast {
    /// `p` with the Stribeck exponent `exponent` (`None`: 2).
    pub(crate) fn new(p: &LugreParams<f64>, exponent: Option<f64>) -> Fast {
        Fast {
            s0: p.sigma0,
            s1: p.sigma1,
            pos: Curve::new(&p.positive, exponent),
            neg: Curve::new(&p.negative, exponent),
        }
    }

    /// `scale*g(v)` as in [`LugreParams::eval`].
    #[inline(always)]
    pub(crate) fn g<S: Shape>(&self, shape: S, v: f64, scale: f64) -> f64 {
        let c = if v >= 0.0 { &self.pos } else { &self.neg };
        scale * shape.g(c, v)
    }

    /// `(g, F)` of [`LugreParams::eval`] (or `eval_shaped`).
    #[inline(always)]
    pub(crate) fn eval<S: Shape>(&self, shape: S, z: f64, v: f64, scale: f64) -> (f64, f64) {
        let c = if v >= 0.0 { &self.pos } else { &self.neg };
        let g = scale * shape.g(c, v);
        (g, self.force(c, z, v, g))
    }

    /// `scale*g(v)` with the levels raised by `level` [N] (a `load_friction`).
    #[inline(always)]
    pub(crate) fn g_level<S: Shape>(&self, shape: S, v: f64, scale: f64, level: f64) -> f64 {
        let c = if v >= 0.0 { &self.pos } else { &self.neg };
        scale * shape.g_level(c, v, level)
    }

    /// `(g, F)` of `effects::eval_loaded`: [`Fast::eval`] with the levels raised by
    /// `level` [N].
    #[inline(always)]
    pub(crate) fn eval_level<S: Shape>(
        &self,
        shape: S,
        z: f64,
        v: f64,
        scale: f64,
        level: f64,
    ) -> (f64, f64) {
        let c = if v >= 0.0 { &self.pos } else { &self.neg };
        let g = scale * shape.g_level(c, v, level);
        (g, self.force(c, z, v, g))
    }

    #[inline(always)]
    fn force(&self, c: &Curve, z: f64, v: f64, g: f64) -> f64 {
        let zdot = v - self.s0 * v.abs() * z / g;
        self.s0 * z + self.s1 * zdot + c.s2 * v
    }

    /// [`LugreParams::advance_z`].
    #[inline(always)]
    pub(crate) fn advance_z(&self, z: f64, v: f64, g: f64, h: f64) -> f64 {
        if v == 0.0 {
            return z;
        }
        let sign = if v > 0.0 { 1.0 } else { -1.0 };
        let zss = sign * g / self.s0;
        zss + (z - zss) * (-(self.s0 * v.abs() * h / g)).exp()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::servo::effects::eval_loaded;

    #[test]
    fn bit_identical_to_the_plain_evaluation() {
        let mut p = crate::servo::Model::paper().friction;
        let mut speeds = vec![0.0, 1e-300, -1e-300];
        for k in 0..4000 {
            let v = 1e-5 * 1.004f64.powi(k);
            speeds.push(v);
            speeds.push(-v);
        }
        for (fc, fs) in [(28.7, 60.2), (1.0, 1e6), (5.0, 5.0), (1e-3, 2e-3)] {
            p.positive.fc = fc;
            p.positive.fs = fs;
            p.negative.fc = 0.9 * fc;
            p.negative.fs = 0.9 * fs;
            for ex in [None, Some(0.7), Some(2.0), Some(3.5)] {
                let f = Fast::new(&p, ex);
                for &v in &speeds {
                    for (z, sc) in [(0.0, 1.0), (3e-4, 0.9), (-2e-4, 1.3)] {
                        let want = match ex {
                            None => p.eval(z, v, sc),
                            Some(e) => p.eval_shaped(z, v, sc, e),
                        };
                        let got = match ex {
                            None => f.eval(Square, z, v, sc),
                            Some(e) => f.eval(Power(e), z, v, sc),
                        };
                        assert_eq!(want.0.to_bits(), got.0.to_bits(), "g at {v} {ex:?}");
                        assert_eq!(want.1.to_bits(), got.1.to_bits(), "F at {v} {ex:?}");
                        let h = 1e-4;
                        assert_eq!(
                            p.advance_z(z, v, want.0, h).to_bits(),
                            f.advance_z(z, v, got.0, h).to_bits()
                        );
                        for level in [0.0, 1e-9, 0.37, 250.0] {
                            let want = eval_loaded(&p, z, v, sc, level, ex);
                            let got = match ex {
                                None => f.eval_level(Square, z, v, sc, level),
                                Some(e) => f.eval_level(Power(e), z, v, sc, level),
                            };
                            assert_eq!(want.0.to_bits(), got.0.to_bits(), "g at {v} {level}");
                            assert_eq!(want.1.to_bits(), got.1.to_bits(), "F at {v} {level}");
                        }
                        // (a level of zero is the plain evaluation)
                        let plain = eval_loaded(&p, z, v, sc, 0.0, ex);
                        assert_eq!(plain.1.to_bits(), want.1.to_bits());
                    }
                }
            }
        }
    }
}
