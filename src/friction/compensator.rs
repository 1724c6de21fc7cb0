//! Friction feed-forward for an embedded controller: a LuGre observer driven by the
//! reference (or measured) velocity.
//!
//! `step` allocates nothing, never panics, and works in `f32` or `f64` without `std`.

use super::{LugreParams, ParamError};
use num_traits::Float;

/// LuGre friction observer: call [`Compensator::step`] once per control period.
///
/// ```
/// use lugre::friction::{Compensator, LugreParams, StaticSet};
/// let s = StaticSet::<f32>::new(28.7, 60.2, 332.5, 0.01).unwrap();
/// let mut c = Compensator::new(LugreParams::new(1e5, 31.62, s, s).unwrap());
/// let mut f = 0.0f32;
/// for _ in 0..10_000 {
///     f = c.step(0.05, 1e-4);
/// }
/// assert!((f - s.stribeck(0.05)).abs() < 1e-2);
/// ```
#[derive(Debug, Clone, Copy)]
pub struct Compensator<T = f64> {
    params: LugreParams<T>,
    z: T,
}

impl<T: Float> Compensator<T> {
    /// A compensator with the bristle state at rest (`z = 0`).
    pub fn new(params: LugreParams<T>) -> Self {
        Self {
            params,
            z: T::zero(),
        }
    }

    /// Validate the parameters first.
    pub fn try_new(params: LugreParams<T>) -> Result<Self, ParamError> {
        params.validate()?;
        Ok(Self::new(params))
    }

    /// Friction force at the current state and velocity `v`, then advance the bristle
    /// state exactly over `dt` with `v` held. A non-finite `v` or `dt` leaves the state
    /// unchanged and returns the force at `v = 0`.
    #[inline]
    pub fn step(&mut self, v: T, dt: T) -> T {
        if !v.is_finite() || !dt.is_finite() || dt < T::zero() {
            return self.params.sigma0 * self.z;
        }
        let (g, f, _) = self.params.eval(self.z, v, T::one());
        self.z = self.params.advance_z(self.z, v, g, dt);
        f
    }

    /// The bristle deflection `z` [m].
    pub fn state(&self) -> T {
        self.z
    }

    /// Set the bristle deflection, clamped to the physical range `|z| <= max(fs)/sigma0`.
    pub fn set_state(&mut self, z: T) {
        let zmax = self.params.max_fs() / self.params.sigma0;
        self.z = if z.is_finite() {
            z.max(-zmax).min(zmax)
        } else {
            T::zero()
        };
    }

    /// Back to rest.
    pub fn reset(&mut self) {
        self.z = T::zero();
    }

    /// The parameters in use.
    pub fn params(&self) -> &LugreParams<T> {
        &self.params
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::friction::StaticSet;

    #[test]
    fn non_finite_input_keeps_state() {
        let s = StaticSet::new(1.0, 2.0, 0.5, 0.01).unwrap();
        let mut c = Compensator::new(LugreParams::new(1e4, 1.0, s, s).unwrap());
        c.step(0.1, 1e-3);
        let z = c.state();
        let f = c.step(f64::NAN, 1e-3);
        assert_eq!(c.state(), z);
        assert!(f.is_finite());
    }
}
