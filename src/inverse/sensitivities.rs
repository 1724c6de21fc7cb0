//! The sensitivities of the LuGre force along a record to the base friction
//! parameters: [`Record::base_sensitivities`], the bristle state's derivatives carried
//! exactly through its update.

use super::{exponent_of, Record};
use crate::error::{Error, Result};
use crate::friction::StaticSet;
use crate::servo::effects::g_loaded;
use crate::servo::Model;

/// A base friction parameter, by its path in the model file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BaseParam {
    /// `fc` of a set (`true`: positive).
    Fc(bool),
    /// `fs` of a set.
    Fs(bool),
    /// `sigma2` of a set.
    Sigma2(bool),
    /// `vs` of a set.
    Vs(bool),
    /// `sigma0`.
    Sigma0,
    /// `sigma1`.
    Sigma1,
}

impl BaseParam {
    /// Parse a path such as `positive.fc` or `sigma0`.
    pub fn parse(name: &str) -> Result<BaseParam> {
        let side = |s: &str| match s {
            "positive" => Some(true),
            "negative" => Some(false),
            _ => None,
        };
        let bad = || {
            Error::input(
                "names",
                format!(
                    "unknown friction parameter {name:?}: use sigma0, sigma1 or \
                     positive/negative.fc, .fs, .sigma2, .vs"
                ),
            )
        };
        match name {
            "sigma0" => return Ok(BaseParam::Sigma0),
            "sigma1" => return Ok(BaseParam::Sigma1),
            _ => {}
        }
        let (s, k) = name.split_once('.').ok_or_else(bad)?;
        let pos = side(s).ok_or_else(bad)?;
        match k {
            "fc" => Ok(BaseParam::Fc(pos)),
            "fs" => Ok(BaseParam::Fs(pos)),
            "sigma2" => Ok(BaseParam::Sigma2(pos)),
            "vs" => Ok(BaseParam::Vs(pos)),
            _ => Err(bad()),
        }
    }

    /// `(d g/d theta, d sigma2/d theta)` of the set that acts at the speed where
    /// `stribeck_e` gives `(e, pw)` (unscaled).
    #[inline(always)]
    fn dg(
        self,
        set: &StaticSet<f64>,
        positive: bool,
        (e, pw): (f64, f64),
        exponent: f64,
    ) -> (f64, f64) {
        let own = |p: bool| p == positive;
        match self {
            BaseParam::Fc(p) if own(p) => (1.0 - e, 0.0),
            BaseParam::Fs(p) if own(p) => (e, 0.0),
            BaseParam::Vs(p) if own(p) => ((set.fs - set.fc) * e * exponent * pw / set.vs, 0.0),
            BaseParam::Sigma2(p) if own(p) => (0.0, 1.0),
            _ => (0.0, 0.0),
        }
    }
}

/// `(exp(-|v/vs|^n), |v/vs|^n)`.
#[inline(always)]
fn stribeck_e(set: &StaticSet<f64>, v: f64, exponent: f64) -> (f64, f64) {
    let r = (v / set.vs).abs();
    let p = if exponent == 2.0 {
        r * r
    } else {
        r.powf(exponent)
    };
    ((-p).exp(), p)
}

/// The value at the middle of each sample interval (the last sample kept).
fn midpoints(a: &[f64]) -> Vec<f64> {
    let n = a.len();
    let mut h = Vec::with_capacity(n);
    for k in 0..n.saturating_sub(1) {
        h.push(0.5 * (a[k] + a[k + 1]));
    }
    if n > 0 {
        h.push(a[n - 1]);
    }
    h
}

/// Sensitivities of the LuGre force along a record.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Sensitivities {
    /// The unfiltered LuGre force [N] (as [`Record::base_friction`]).
    pub force: Vec<f64>,
    /// One filtered column `d filt(F)/d theta` per parameter.
    pub columns: Vec<Vec<f64>>,
    /// Whether each unfiltered column has a non-zero element.
    pub nonzero: Vec<bool>,
}

impl Record {
    /// The LuGre force of [`Record::base_friction`] and its filtered derivatives with
    /// respect to `params`, propagated exactly through the bristle update. (A
    /// `load_friction` raises both levels by the same amount, which depends on none of
    /// the parameters: the derivatives keep their form.) The parameters go in two
    /// halves, each carried along the record on its own thread (rayon); every column
    /// is the same, number for number, as in one pass of all of them.
    pub fn base_sensitivities(&self, model: &Model, params: &[BaseParam]) -> Sensitivities {
        let half = params.len().div_ceil(2);
        let ((force, mut cols), (_, rest)) = if params.len() >= 2 {
            rayon::join(
                || self.sensitivity_pass(model, &params[..half], true),
                || self.sensitivity_pass(model, &params[half..], false),
            )
        } else {
            (
                self.sensitivity_pass(model, params, true),
                (Vec::new(), Vec::new()),
            )
        };
        cols.extend(rest);
        let nonzero = cols.iter().map(|c| c.iter().any(|&x| x != 0.0)).collect();
        self.filt_in_place(&mut cols);
        Sensitivities {
            force,
            columns: cols,
            nonzero,
        }
    }

    /// The unfiltered columns of `params` along the record, and the LuGre force when
    /// `with_force` (else no force).
    fn sensitivity_pass(
        &self,
        model: &Model,
        params: &[BaseParam],
        with_force: bool,
    ) -> (Vec<f64>, Vec<Vec<f64>>) {
        let n = self.len();
        let q = params.len();
        let exponent = exponent_of(model);
        let ex = exponent.unwrap_or(2.0);
        let p = &model.friction;
        let s0 = p.sigma0;
        let s1 = p.sigma1;
        let s = self.friction_scale(model);
        let sh = s.as_deref().map(midpoints);
        let lev = self.friction_level(model);
        let lh = lev.as_deref().map(midpoints);
        let vh = midpoints(&self.v);
        let mut force = vec![0.0; if with_force { n } else { 0 }];
        let mut cols = vec![vec![0.0; n]; q];
        let mut dz = vec![0.0; q];
        let mut z = 0.0;
        for k in 0..n {
            // force at z_k, v_k
            let v = self.v[k];
            let sc = s.as_ref().map_or(1.0, |s| s[k]);
            let pos = v >= 0.0;
            let set = p.set(v);
            let g = sc * g_loaded(set, v, lev.as_ref().map_or(0.0, |l| l[k]), exponent);
            let w = v - s0 * v.abs() * z / g;
            if with_force {
                force[k] = s0 * z + s1 * w + set.sigma2 * v;
            }
            // (one exponential for every parameter of the set; unused without fc, fs, vs)
            let e = stribeck_e(set, v, ex);
            for (j, par) in params.iter().enumerate() {
                let (dg0, ds2) = par.dg(set, pos, e, ex);
                let dg = sc * dg0;
                let ds0 = if *par == BaseParam::Sigma0 { 1.0 } else { 0.0 };
                let ds1 = if *par == BaseParam::Sigma1 { 1.0 } else { 0.0 };
                let dw = -v.abs() * (ds0 * z / g + s0 * dz[j] / g - s0 * z * dg / (g * g));
                cols[j][k] = ds0 * z + s0 * dz[j] + ds1 * w + s1 * dw + ds2 * v;
            }
            // advance z over [t_k, t_k+1) with the midpoint velocity and scale
            if k + 1 == n {
                break;
            }
            let u = vh[k];
            if u == 0.0 {
                continue;
            }
            let su = sh.as_ref().map_or(1.0, |s| s[k]);
            let upos = u >= 0.0;
            let uset = p.set(u);
            let gh = su * g_loaded(uset, u, lh.as_ref().map_or(0.0, |l| l[k]), exponent);
            let sign = if u > 0.0 { 1.0 } else { -1.0 };
            let zss = sign * gh / s0;
            let e = (-(s0 * u.abs() * self.dt / gh)).exp();
            let eu = stribeck_e(uset, u, ex);
            for (j, par) in params.iter().enumerate() {
                let dgh = su * par.dg(uset, upos, eu, ex).0;
                let ds0 = if *par == BaseParam::Sigma0 { 1.0 } else { 0.0 };
                let dzss = sign * (dgh / s0 - gh * ds0 / (s0 * s0));
                let da = u.abs() * self.dt * (ds0 / gh - s0 * dgh / (gh * gh));
                dz[j] = dzss * (1.0 - e) + e * dz[j] - (z - zss) * e * da;
            }
            z = p.advance_z(z, u, gh, self.dt);
        }
        (force, cols)
    }
}
