//! LuGre friction with one static (Stribeck) set per direction.
//!
//! The model of Canudas de Wit, Olsson, Åström and Lischinsky (IEEE TAC 1995):
//!
//! ```text
//! F    = sigma0*z + sigma1*z' + sigma2*v
//! z'   = v - sigma0*|v|*z/g(v)
//! g(v) = fc + (fs - fc)*exp(-(v/vs)^2)
//! ```
//!
//! with the `positive` set `(fc, fs, sigma2, vs)` while `v >= 0` and the `negative` set
//! while `v < 0`, as in the seed paper's eq. 9 and the project's model files.
//!
//! The bristle state is advanced *exactly* over a step with the velocity held: the
//! equation for `z` is then linear with constant coefficients, so
//! `z(h) = zss + (z0 - zss)*exp(-sigma0*|v|*h/g(v))`. The update is unconditionally
//! stable and keeps `|z| <= max(fs)/sigma0` once it starts there, whatever the step.
//!
//! Everything here is `no_std` and generic over `f32`/`f64`, for embedded controllers.

pub mod compensator;

pub use compensator::Compensator;

use core::fmt;
use num_traits::Float;

/// A parameter that fails validation: which one, its value and what is wrong.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ParamError {
    /// Path of the parameter, e.g. `friction.positive.vs`.
    pub name: &'static str,
    /// The offending value (as f64 for reporting).
    pub value: f64,
    /// What the value must satisfy.
    pub requirement: &'static str,
}

impl fmt::Display for ParamError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "parameter {} = {} is invalid: it {}",
            self.name, self.value, self.requirement
        )
    }
}

pub(crate) fn check_positive<T: Float>(name: &'static str, value: T) -> Result<(), ParamError> {
    let ok = value.is_finite() && value > T::zero();
    if ok {
        Ok(())
    } else {
        Err(ParamError {
            name,
            value: value.to_f64().unwrap_or(f64::NAN),
            requirement: "must be a finite number greater than zero",
        })
    }
}

pub(crate) fn check_nonnegative<T: Float>(name: &'static str, value: T) -> Result<(), ParamError> {
    let ok = value.is_finite() && value >= T::zero();
    if ok {
        Ok(())
    } else {
        Err(ParamError {
            name,
            value: value.to_f64().unwrap_or(f64::NAN),
            requirement: "must be a finite number, zero or greater",
        })
    }
}

/// Static (Stribeck) friction parameters of one direction of motion.
///
/// ```
/// use lugre::friction::StaticSet;
/// let s = StaticSet::<f64>::new(28.7, 60.2, 332.5, 0.01).unwrap();
/// assert!((s.g(0.0) - 60.2).abs() < 1e-12);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StaticSet<T = f64> {
    /// Coulomb friction level [N].
    pub fc: T,
    /// Static (break-away) friction level [N], `fs >= fc`.
    pub fs: T,
    /// Viscous coefficient [N s/m] (the seed paper's alpha).
    pub sigma2: T,
    /// Stribeck velocity [m/s].
    pub vs: T,
}

impl<T: Float> StaticSet<T> {
    /// Build and validate a static set.
    pub fn new(fc: T, fs: T, sigma2: T, vs: T) -> Result<Self, ParamError> {
        let s = Self { fc, fs, sigma2, vs };
        s.validate("")?;
        Ok(s)
    }

    /// Check the set; `prefix` selects the names used in errors (`positive`/`negative`).
    pub fn validate(&self, prefix: &'static str) -> Result<(), ParamError> {
        let (nfc, nfs, ns2, nvs) = match prefix {
            "negative" => (
                "friction.negative.fc",
                "friction.negative.fs",
                "friction.negative.sigma2",
                "friction.negative.vs",
            ),
            "positive" => (
                "friction.positive.fc",
                "friction.positive.fs",
                "friction.positive.sigma2",
                "friction.positive.vs",
            ),
            _ => ("fc", "fs", "sigma2", "vs"),
        };
        check_positive(nfc, self.fc)?;
        check_positive(nfs, self.fs)?;
        check_nonnegative(ns2, self.sigma2)?;
        check_positive(nvs, self.vs)?;
        if self.fs < self.fc {
            return Err(ParamError {
                name: nfs,
                value: self.fs.to_f64().unwrap_or(f64::NAN),
                requirement: "must be at least fc (static friction below Coulomb friction); swap them or raise fs",
            });
        }
        Ok(())
    }

    /// `g(v) = fc + (fs - fc)*exp(-(v/vs)^2)` [N].
    #[inline(always)]
    pub fn g(&self, v: T) -> T {
        let r = v / self.vs;
        self.fc + (self.fs - self.fc) * (-(r * r)).exp()
    }

    /// Generalised Stribeck curve `g(v) = fc + (fs - fc)*exp(-|v/vs|^exponent)` [N]
    /// (the `stribeck_shape` effect). [`StaticSet::g`] is the case `exponent == 2`,
    /// kept apart so that the usual curve needs no `powf`.
    ///
    /// ```
    /// use lugre::friction::StaticSet;
    /// let s = StaticSet::<f64>::new(28.7, 60.2, 332.5, 0.01).unwrap();
    /// assert!((s.g_shaped(0.02, 2.0) - s.g(0.02)).abs() < 1e-12);
    /// ```
    #[inline(always)]
    pub fn g_shaped(&self, v: T, exponent: T) -> T {
        let r = (v / self.vs).abs();
        self.fc + (self.fs - self.fc) * (-(r.powf(exponent))).exp()
    }

    /// Steady-state friction `sign(v)*g(v) + sigma2*v`, zero at `v == 0`.
    #[inline]
    pub fn stribeck(&self, v: T) -> T {
        if v == T::zero() {
            T::zero()
        } else {
            v.signum() * self.g(v) + self.sigma2 * v
        }
    }

    /// Passivity bound on sigma1 (Barabanov & Ortega 2000): `4*sigma2*fc/(fs - fc)`,
    /// infinite when `fs == fc`.
    pub fn sigma1_passivity_bound(&self) -> T {
        let d = self.fs - self.fc;
        if d <= T::zero() {
            T::infinity()
        } else {
            T::from(4.0).unwrap() * self.sigma2 * self.fc / d
        }
    }
}

/// LuGre parameters: bristle stiffness and damping, and one static set per direction.
///
/// ```
/// use lugre::friction::{LugreParams, StaticSet};
/// let p = LugreParams::new(
///     1e5, 31.62,
///     StaticSet::new(28.7, 60.2, 332.5, 0.01).unwrap(),
///     StaticSet::new(28.5, 60.1, 333.0, 0.01).unwrap(),
/// ).unwrap();
/// assert!(p.is_passive());
/// assert!((p.stribeck(-0.1) + (28.5 + 31.6 * (-100.0f64).exp() + 33.3)).abs() < 1e-9);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LugreParams<T = f64> {
    /// Bristle stiffness [N/m].
    pub sigma0: T,
    /// Bristle damping [N s/m].
    pub sigma1: T,
    /// Static set while `v >= 0`.
    pub positive: StaticSet<T>,
    /// Static set while `v < 0`.
    pub negative: StaticSet<T>,
}

impl<T: Float> LugreParams<T> {
    /// Build and validate.
    pub fn new(
        sigma0: T,
        sigma1: T,
        positive: StaticSet<T>,
        negative: StaticSet<T>,
    ) -> Result<Self, ParamError> {
        let p = Self {
            sigma0,
            sigma1,
            positive,
            negative,
        };
        p.validate()?;
        Ok(p)
    }

    /// Check every parameter.
    pub fn validate(&self) -> Result<(), ParamError> {
        check_positive("friction.sigma0", self.sigma0)?;
        check_nonnegative("friction.sigma1", self.sigma1)?;
        self.positive.validate("positive")?;
        self.negative.validate("negative")?;
        Ok(())
    }

    /// True when sigma1 satisfies the passivity bound for both directions.
    pub fn is_passive(&self) -> bool {
        self.sigma1 <= self.positive.sigma1_passivity_bound()
            && self.sigma1 <= self.negative.sigma1_passivity_bound()
    }

    /// The static set that applies at velocity `v`.
    #[inline(always)]
    pub fn set(&self, v: T) -> &StaticSet<T> {
        if v >= T::zero() {
            &self.positive
        } else {
            &self.negative
        }
    }

    /// Largest static level of both directions [N].
    pub fn max_fs(&self) -> T {
        self.positive.fs.max(self.negative.fs)
    }

    /// Steady-state (Stribeck) friction force at `v`.
    #[inline]
    pub fn stribeck(&self, v: T) -> T {
        self.set(v).stribeck(v)
    }

    /// `(g, F, zdot)` at bristle state `z` and velocity `v`, with the static levels
    /// multiplied by `scale` (1 for the plain model).
    #[inline(always)]
    pub fn eval(&self, z: T, v: T, scale: T) -> (T, T, T) {
        let s = self.set(v);
        let g = scale * s.g(v);
        let zdot = v - self.sigma0 * v.abs() * z / g;
        let f = self.sigma0 * z + self.sigma1 * zdot + s.sigma2 * v;
        (g, f, zdot)
    }

    /// As [`LugreParams::eval`] with the generalised curve [`StaticSet::g_shaped`].
    #[inline(always)]
    pub fn eval_shaped(&self, z: T, v: T, scale: T, exponent: T) -> (T, T, T) {
        let s = self.set(v);
        let g = scale * s.g_shaped(v, exponent);
        let zdot = v - self.sigma0 * v.abs() * z / g;
        let f = self.sigma0 * z + self.sigma1 * zdot + s.sigma2 * v;
        (g, f, zdot)
    }

    /// Exact bristle update over `h` with `v` held, given `g = g(v)`.
    #[inline(always)]
    pub fn advance_z(&self, z: T, v: T, g: T, h: T) -> T {
        if v == T::zero() {
            return z;
        }
        // sign(v) as a branch-free select (v != 0 here), cheaper than signum()
        let sign = if v > T::zero() { T::one() } else { -T::one() };
        let zss = sign * g / self.sigma0;
        zss + (z - zss) * (-(self.sigma0 * v.abs() * h / g)).exp()
    }
}

/// LuGre force driven by a sampled velocity: `out[k]` is the force at state `z_k` and
/// `v[k]`; then `z` advances exactly over `dt` with `v[k]` held. Returns the final `z`.
///
/// `z_out`, when given, receives `z_k`. Lengths must match (checked by the caller).
pub fn friction_force_into<T: Float>(
    p: &LugreParams<T>,
    v: &[T],
    dt: T,
    z0: T,
    out: &mut [T],
    mut z_out: Option<&mut [T]>,
) -> T {
    let mut z = z0;
    for (k, (&vk, o)) in v.iter().zip(out.iter_mut()).enumerate() {
        let (g, f, _) = p.eval(z, vk, T::one());
        *o = f;
        if let Some(zo) = z_out.as_deref_mut() {
            zo[k] = z;
        }
        z = p.advance_z(z, vk, g, dt);
    }
    z
}

/// As [`friction_force_into`] with one hold interval per sample (`dt[k]` follows `v[k]`).
pub fn friction_force_varstep_into<T: Float>(
    p: &LugreParams<T>,
    v: &[T],
    dt: &[T],
    z0: T,
    out: &mut [T],
    mut z_out: Option<&mut [T]>,
) -> T {
    let mut z = z0;
    for (k, ((&vk, &h), o)) in v.iter().zip(dt.iter()).zip(out.iter_mut()).enumerate() {
        let (g, f, _) = p.eval(z, vk, T::one());
        *o = f;
        if let Some(zo) = z_out.as_deref_mut() {
            zo[k] = z;
        }
        z = p.advance_z(z, vk, g, h);
    }
    z
}

/// As [`friction_force_into`] and [`friction_force_varstep_into`] with the options of
/// the diagnosis: `dt` holds one interval for every sample or one per sample; `scale`,
/// when given (one value per sample), multiplies `g(v[k])` at sample `k`; `exponent`,
/// when given, replaces the Stribeck exponent 2 ([`StaticSet::g_shaped`]).
///
/// Lengths must match (checked by the caller). Returns the final `z`.
#[allow(clippy::too_many_arguments)]
pub fn friction_force_general_into<T: Float>(
    p: &LugreParams<T>,
    v: &[T],
    dt: &[T],
    z0: T,
    scale: Option<&[T]>,
    exponent: Option<T>,
    out: &mut [T],
    mut z_out: Option<&mut [T]>,
) -> T {
    let mut z = z0;
    let one_dt = dt.len() == 1;
    for (k, (&vk, o)) in v.iter().zip(out.iter_mut()).enumerate() {
        let s = match scale {
            Some(sc) => sc[k],
            None => T::one(),
        };
        let (g, f, _) = match exponent {
            Some(e) => p.eval_shaped(z, vk, s, e),
            None => p.eval(z, vk, s),
        };
        *o = f;
        if let Some(zo) = z_out.as_deref_mut() {
            zo[k] = z;
        }
        z = p.advance_z(z, vk, g, if one_dt { dt[0] } else { dt[k] });
    }
    z
}

/// Classic fourth-order Runge-Kutta step of the bristle equation over `h` with `v` held.
///
/// For comparison with the exact update; its error falls as `h^4`.
pub fn rk4_z<T: Float>(p: &LugreParams<T>, z: T, v: T, h: T) -> T {
    let f = |zz: T| p.eval(zz, v, T::one()).2;
    let two = T::from(2.0).unwrap();
    let six = T::from(6.0).unwrap();
    let k1 = f(z);
    let k2 = f(z + h / two * k1);
    let k3 = f(z + h / two * k2);
    let k4 = f(z + h * k3);
    z + h / six * (k1 + two * k2 + two * k3 + k4)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn paper() -> LugreParams<f64> {
        LugreParams::new(
            1e5,
            31.62,
            StaticSet::new(28.7, 60.2, 332.5, 0.01).unwrap(),
            StaticSet::new(28.5, 60.1, 333.0, 0.01).unwrap(),
        )
        .unwrap()
    }

    #[test]
    fn rejects_bad_parameters() {
        let e = StaticSet::new(30.0, 20.0, 1.0, 0.01).unwrap_err();
        assert_eq!(e.name, "fs");
        assert!(StaticSet::new(30.0, 40.0, 1.0, 0.0).is_err());
        assert!(StaticSet::new(f64::NAN, 40.0, 1.0, 0.1).is_err());
        let s = StaticSet::new(1.0, 2.0, 1.0, 0.1).unwrap();
        let e = LugreParams::new(-1.0, 0.0, s, s).unwrap_err();
        assert_eq!(e.name, "friction.sigma0");
        let bad = StaticSet {
            fc: 1.0,
            fs: 2.0,
            sigma2: 1.0,
            vs: -0.1,
        };
        let e = LugreParams::new(1.0, 0.0, s, bad).unwrap_err();
        assert_eq!(e.name, "friction.negative.vs");
        assert!(e.to_string().contains("greater than zero"));
    }

    #[test]
    fn stribeck_values() {
        let p = paper();
        assert_eq!(p.stribeck(0.0), 0.0);
        let v = 0.01;
        let want = 28.7 + (60.2 - 28.7) * (-1.0f64).exp() + 332.5 * v;
        assert!((p.stribeck(v) - want).abs() < 1e-12);
        assert!(p.stribeck(-v) < 0.0);
    }

    #[test]
    fn exact_update_matches_rk4_on_fine_steps() {
        let p = paper();
        for &v in &[1e-4, 3e-3, 0.05, -0.02, 0.4] {
            let h = 1e-4;
            let exact = p.advance_z(0.0, v, p.set(v).g(v), h);
            let mut z = 0.0;
            let n = 1000;
            for _ in 0..n {
                z = rk4_z(&p, z, v, h / n as f64);
            }
            assert!(
                (z - exact).abs() <= 1e-12 * (1.0 + exact.abs() * 1e6),
                "v={v}"
            );
        }
    }

    #[test]
    fn general_kernel_reduces_to_the_plain_one() {
        let p = paper();
        let v: [f64; 6] = [0.0, 1e-3, 0.02, -0.004, -0.3, 0.1];
        let (mut a, mut b) = ([0.0; 6], [0.0; 6]);
        friction_force_into(&p, &v, 1e-3, 1e-5, &mut a, None);
        friction_force_general_into(&p, &v, &[1e-3], 1e-5, None, None, &mut b, None);
        assert_eq!(a, b);
        // exponent 2 is the usual curve; scale multiplies g
        let ones = [1.0; 6];
        friction_force_general_into(&p, &v, &[1e-3], 1e-5, Some(&ones), Some(2.0), &mut b, None);
        for (x, y) in a.iter().zip(&b) {
            assert!((x - y).abs() <= 1e-12 * x.abs().max(1.0));
        }
        let s = p.positive;
        assert!((s.g_shaped(0.01, 1.0) - (s.fc + (s.fs - s.fc) * (-1.0f64).exp())).abs() < 1e-12);
        let (g, _, _) = p.eval(0.0, 0.02, 1.5);
        assert!((g - 1.5 * s.g(0.02)).abs() < 1e-12);
    }

    #[test]
    fn f32_works() {
        let s = StaticSet::<f32>::new(28.7, 60.2, 332.5, 0.01).unwrap();
        let p = LugreParams::<f32>::new(1e5, 31.62, s, s).unwrap();
        let mut out = [0.0f32; 1000];
        let v = [0.01f32; 1000];
        friction_force_into(&p, &v, 1e-3, 0.0, &mut out, None);
        assert!((out[999] - p.stribeck(0.01)).abs() < 1e-2);
    }
}
