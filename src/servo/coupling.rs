//! The load behind the compliant coupling of the `resonance` effect, driven by the
//! measured motor motion.
//!
//! With a `resonance`, the encoder measures the motor `(1 - r)*M`; the friction and the
//! other effects act on the load `r*M`, joined to the motor by a spring `k` and a damper
//! `c`. The motor force that the model needs is `(1 - r)*M*a_m + F_s`, where
//! `F_s = k*(x_m - x_l) + c*(v_m - v_l)` is the force the coupling passes to the load.
//! The load's motion `x_l` is not measured: [`load_coupling`] simulates it, driven by the
//! sampled motor position and velocity (linear interpolation between samples), with
//! the same plant step as the servo simulation (exact bristle update, semi-implicit
//! Euler). The algorithm is fixed in `docs/DESIGN.md` ("Load behind the coupling") and
//! repeated step for step by `lugre.reference.load_coupling`.
//!
//! ```
//! use lugre::servo::{load_coupling, CouplingOptions, Model};
//! let mut m = Model::paper();
//! m.effects.push(lugre::servo::Effect::Resonance {
//!     frequency_hz: 22.0, damping_ratio: 0.04, load_fraction: 0.75 });
//! // the motor at rest: the load stays at rest and the coupling carries no force
//! let x = vec![0.0; 100];
//! let v = vec![0.0; 100];
//! let r = load_coupling(&m, &x, &v, 1e-4, &CouplingOptions::default()).unwrap();
//! assert!(r.force.iter().all(|&f| f == 0.0));
//! ```

use super::fast::{Fast, Power, Shape, Square};
use super::model::{Effect, Model};
use super::sim::TwoMass;
use crate::error::{check_finite, check_len, check_scale, Error, Result};
use crate::friction::LugreParams;

/// Most substeps allowed per sample interval (a guard against absurd `dt`).
pub const MAX_SUBSTEPS: f64 = 1e6;

/// Options of [`load_coupling`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CouplingOptions<'a> {
    /// One positive factor per sample multiplying `g(v)` (position- or time-dependent
    /// friction levels); `None` for 1.
    pub scale: Option<&'a [f64]>,
    /// Further force on the load per sample [N] (cogging, springs, offsets, drag
    /// evaluated by the caller); `None` for 0.
    pub extra: Option<&'a [f64]>,
    /// Initial bristle deflection [m].
    pub z0: f64,
    /// Multiplier (>= 1) of the automatic number of substeps per sample interval.
    pub substeps: usize,
}

impl Default for CouplingOptions<'_> {
    fn default() -> Self {
        Self {
            scale: None,
            extra: None,
            z0: 0.0,
            substeps: 1,
        }
    }
}

/// The load's trajectory at the sample instants (each at the state before the step
/// that follows the sample).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LoadTrajectory {
    /// Force the coupling passes to the load, `k*(x_m - x_l) + c*(v_m - v_l)` [N].
    pub force: Vec<f64>,
    /// Load position [m].
    pub x: Vec<f64>,
    /// Load velocity [m/s].
    pub v: Vec<f64>,
    /// Bristle deflection of the load's friction [m].
    pub z: Vec<f64>,
}

/// The load side of a model's `resonance`: coupling, load mass and friction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Coupling {
    /// Coupling stiffness `k = r*M*(2*pi*frequency)^2` [N/m].
    pub k: f64,
    /// Coupling damping `c = 2*damping_ratio*sqrt(k*r*M)` [N s/m].
    pub c: f64,
    /// Load mass `r*M` [kg].
    pub ml: f64,
    /// The load's friction.
    pub friction: LugreParams<f64>,
    /// Stribeck exponent of a `stribeck_shape` effect (`None`: 2).
    pub exponent: Option<f64>,
}

impl Coupling {
    /// The load side of `model`; [`Error::Model`] on `effects` without a `resonance`.
    pub fn from_model(model: &Model) -> Result<Coupling> {
        let (f, zeta, r) = model
            .effects
            .iter()
            .find_map(|e| match e {
                Effect::Resonance {
                    frequency_hz,
                    damping_ratio,
                    load_fraction,
                } => Some((*frequency_hz, *damping_ratio, *load_fraction)),
                _ => None,
            })
            .ok_or_else(|| {
                Error::model(
                    "effects",
                    "has no resonance: the load behind a coupling needs one; add \
                     {\"effect\": \"resonance\", \"frequency\": F, \"damping_ratio\": Z, \
                     \"load_fraction\": R} to the model's effects",
                )
            })?;
        let tm = TwoMass::new(model.total_mass(), f, zeta, r);
        Ok(Coupling {
            k: tm.k,
            c: tm.c,
            ml: tm.ml,
            friction: model.friction,
            exponent: model.stribeck_exponent(),
        })
    }

    /// `w = sqrt((k + sigma0)/(r*M))` [rad/s]: the stiffest case, coupling plus stuck
    /// bristles.
    pub fn stiff_rate(&self) -> f64 {
        ((self.k + self.friction.sigma0) / self.ml).sqrt()
    }

    /// `d = (c + sigma1 + max(sigma2))/(r*M)` [1/s]: the strongest damping of the load
    /// (coupling plus stuck bristles plus viscous friction), taken explicitly.
    pub fn damping_rate(&self) -> f64 {
        let s2 = self
            .friction
            .positive
            .sigma2
            .max(self.friction.negative.sigma2);
        (self.c + self.friction.sigma1 + s2) / self.ml
    }

    /// Substeps per sample interval before the `substeps` multiplier:
    /// `max(1, ceil(4*w*dt), ceil(d*dt))`, as a float (checked against
    /// [`MAX_SUBSTEPS`]): `w*h <= 1/4` and `d*h <= 1`.
    pub fn auto_substeps(&self, dt: f64) -> f64 {
        let stiff = (4.0 * self.stiff_rate() * dt).ceil();
        let damp = (self.damping_rate() * dt).ceil();
        stiff.max(damp).max(1.0)
    }
}

/// Check the inputs of [`load_coupling`] (in the order of the NumPy twin).
fn check_inputs(
    cp: &Coupling,
    x: &[f64],
    v: &[f64],
    dt: f64,
    opts: &CouplingOptions,
) -> Result<usize> {
    check_finite("x", x)?;
    check_len("v", v, x.len(), "x")?;
    check_finite("v", v)?;
    if !(dt.is_finite() && dt > 0.0) {
        return Err(Error::parameter(
            "dt",
            dt,
            "must be a finite sample interval greater than zero [s]",
        ));
    }
    if !opts.z0.is_finite() {
        return Err(Error::parameter("z0", opts.z0, "must be finite"));
    }
    if opts.substeps == 0 {
        return Err(Error::parameter("substeps", 0.0, "must be at least 1"));
    }
    if let Some(sc) = opts.scale {
        check_scale(sc, x.len(), "x")?;
    }
    if let Some(ex) = opts.extra {
        check_len("extra", ex, x.len(), "x")?;
        check_finite("extra", ex)?;
    }
    let n = cp.auto_substeps(dt) * opts.substeps as f64;
    if n > MAX_SUBSTEPS {
        return Err(Error::parameter(
            "dt",
            dt,
            format!(
                "needs {n} substeps per sample for the coupling and bristle stiffness \
                 (at most {MAX_SUBSTEPS}): give samples at a shorter interval"
            ),
        ));
    }
    Ok(n as usize)
}

/// Simulate the load of `model`'s `resonance` driven by the motor motion `x`, `v`
/// sampled every `dt`; see the module documentation and `docs/DESIGN.md`.
///
/// Errors: [`Error::Model`] without a `resonance`; [`Error::Input`] on non-finite or
/// mismatched arrays or a non-positive `scale`; [`Error::Parameter`] on `dt <= 0`,
/// non-finite `z0`, `substeps == 0`; [`Error::Data`] if the load's state turns
/// non-finite.
pub fn load_coupling(
    model: &Model,
    x: &[f64],
    v: &[f64],
    dt: f64,
    opts: &CouplingOptions,
) -> Result<LoadTrajectory> {
    let cp = Coupling::from_model(model)?;
    let n_sub = check_inputs(&cp, x, v, dt, opts)?;
    let n = x.len();
    let mut out = LoadTrajectory {
        force: vec![0.0; n],
        x: vec![0.0; n],
        v: vec![0.0; n],
        z: vec![0.0; n],
    };
    let load = Some((&mut out.x[..], &mut out.v[..], &mut out.z[..]));
    run(&cp, x, v, dt, opts, n_sub, &mut out.force, load)?;
    Ok(out)
}

/// The coupling force of [`load_coupling`] alone (the load's trajectory not kept).
pub(crate) fn coupling_force(
    model: &Model,
    x: &[f64],
    v: &[f64],
    dt: f64,
    opts: &CouplingOptions,
) -> Result<Vec<f64>> {
    let cp = Coupling::from_model(model)?;
    let n_sub = check_inputs(&cp, x, v, dt, opts)?;
    let mut force = vec![0.0; x.len()];
    run(&cp, x, v, dt, opts, n_sub, &mut force, None)?;
    Ok(force)
}

/// The load's position, velocity and bristle state at the samples.
type LoadOut<'a> = Option<(&'a mut [f64], &'a mut [f64], &'a mut [f64])>;

/// The loop of [`load_coupling`] on checked inputs, `n_sub` substeps per interval, the
/// coupling force into `force` and the load's state into `load`.
#[allow(clippy::too_many_arguments)]
fn run(
    cp: &Coupling,
    x: &[f64],
    v: &[f64],
    dt: f64,
    opts: &CouplingOptions,
    n_sub: usize,
    force: &mut [f64],
    load: LoadOut<'_>,
) -> Result<()> {
    let fast = Fast::new(&cp.friction, cp.exponent);
    match cp.exponent {
        None => run_shaped(cp, &fast, Square, x, v, dt, opts, n_sub, force, load),
        Some(e) => run_shaped(cp, &fast, Power(e), x, v, dt, opts, n_sub, force, load),
    }
}

/// [`run`] for one shape of the Stribeck curve.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn run_shaped<S: Shape>(
    cp: &Coupling,
    fr: &Fast,
    shape: S,
    x: &[f64],
    v: &[f64],
    dt: f64,
    opts: &CouplingOptions,
    n_sub: usize,
    force: &mut [f64],
    mut load: LoadOut<'_>,
) -> Result<()> {
    let n = x.len();
    if n == 0 {
        return Ok(());
    }
    let (x, v, force) = (&x[..n], &v[..n], &mut force[..n]);
    let (k, c, ml) = (cp.k, cp.c, cp.ml);
    let h = dt / n_sub as f64;
    let nf = n_sub as f64;
    // the interpolation fractions j/n of the substeps after the first
    let fracs: Vec<f64> = (1..n_sub).map(|j| j as f64 / nf).collect();
    let mut xl = x[0];
    let mut vl = v[0];
    let mut z = opts.z0;
    // one substep: the plant step of the load with the motor at (xm, vm)
    let step = |xm: f64, vm: f64, s: f64, fe: f64, xl: &mut f64, vl: &mut f64, z: &mut f64| {
        let fs = k * (xm - *xl) + c * (vm - *vl);
        let (g, ff) = fr.eval(shape, *z, *vl, s);
        let al = (fs - ff - fe) / ml;
        *z = fr.advance_z(*z, *vl, g, h);
        *vl += al * h;
        *xl += *vl * h;
    };
    for i in 0..n {
        let (x0, v0) = (x[i], v[i]);
        force[i] = k * (x0 - xl) + c * (v0 - vl);
        if let Some((ox, ov, oz)) = load.as_mut() {
            ox[i] = xl;
            ov[i] = vl;
            oz[i] = z;
        }
        if i + 1 == n {
            break;
        }
        let s = opts.scale.map_or(1.0, |a| a[i]);
        let fe = opts.extra.map_or(0.0, |a| a[i]);
        let (dx, dv) = (x[i + 1] - x0, v[i + 1] - v0);
        step(x0, v0, s, fe, &mut xl, &mut vl, &mut z);
        for &f in &fracs {
            step(x0 + dx * f, v0 + dv * f, s, fe, &mut xl, &mut vl, &mut z);
        }
        if !(xl.is_finite() && vl.is_finite() && z.is_finite()) {
            return Err(Error::Data(format!(
                "the load behind the coupling diverged after sample {i}: check the \
                 motor motion and the model's resonance"
            )));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn model() -> Model {
        let mut m = Model::paper();
        m.effects.push(Effect::Resonance {
            frequency_hz: 22.0,
            damping_ratio: 0.04,
            load_fraction: 0.75,
        });
        m
    }

    #[test]
    fn needs_a_resonance() {
        let e = load_coupling(
            &Model::paper(),
            &[0.0],
            &[0.0],
            1e-4,
            &CouplingOptions::default(),
        )
        .unwrap_err();
        assert!(matches!(&e, Error::Model { path, .. } if path == "effects"));
        assert!(e.to_string().contains("add"), "{e}");
    }

    #[test]
    fn bad_inputs_are_errors() {
        let m = model();
        let o = CouplingOptions::default();
        let name = |e: Error| match e {
            Error::Input { name, .. } | Error::Parameter { name, .. } => name,
            other => panic!("{other}"),
        };
        assert_eq!(
            name(load_coupling(&m, &[0.0, 1.0], &[0.0], 1e-4, &o).unwrap_err()),
            "v"
        );
        assert_eq!(
            name(load_coupling(&m, &[f64::NAN], &[0.0], 1e-4, &o).unwrap_err()),
            "x"
        );
        assert_eq!(
            name(load_coupling(&m, &[0.0], &[0.0], 0.0, &o).unwrap_err()),
            "dt"
        );
        assert_eq!(
            name(load_coupling(&m, &[0.0], &[0.0], 1e9, &o).unwrap_err()),
            "dt"
        );
        let sc = [0.0];
        let o2 = CouplingOptions {
            scale: Some(&sc),
            ..o
        };
        assert_eq!(
            name(load_coupling(&m, &[0.0], &[0.0], 1e-4, &o2).unwrap_err()),
            "scale"
        );
        let o3 = CouplingOptions {
            extra: Some(&[]),
            ..o
        };
        assert_eq!(
            name(load_coupling(&m, &[0.0], &[0.0], 1e-4, &o3).unwrap_err()),
            "extra"
        );
        let r = load_coupling(&m, &[], &[], 1e-4, &o).unwrap();
        assert!(r.force.is_empty());
    }

    #[test]
    fn heavy_damping_at_coarse_sampling_stays_stable() {
        // damping_ratio 20 sampled at 1 kHz: d*dt = 5.6, so 6 substeps (the stiffness
        // alone would give 1, which diverges)
        let mut m = model();
        m.effects[0] = Effect::Resonance {
            frequency_hz: 22.0,
            damping_ratio: 20.0,
            load_fraction: 0.75,
        };
        let cp = Coupling::from_model(&m).unwrap();
        assert_eq!((4.0 * cp.stiff_rate() * 1e-3).ceil(), 1.0);
        assert_eq!(cp.auto_substeps(1e-3), 6.0);
        let dt = 1e-3;
        let w = 2.0 * core::f64::consts::PI * 2.0;
        let x: Vec<f64> = (0..2000)
            .map(|k| 0.01 * (w * k as f64 * dt).sin())
            .collect();
        let v: Vec<f64> = (0..2000)
            .map(|k| 0.01 * w * (w * k as f64 * dt).cos())
            .collect();
        let r = load_coupling(&m, &x, &v, dt, &CouplingOptions::default()).unwrap();
        assert!(r.force.iter().all(|f| f.abs() < 100.0));
    }

    #[test]
    fn constant_speed_settles_to_friction() {
        // the motor slides at 0.05 m/s: the load follows and the coupling carries the
        // steady friction plus the extra force
        let m = model();
        let n = 40_000;
        let dt = 1e-4;
        let vm = 0.05;
        let x: Vec<f64> = (0..n).map(|k| vm * k as f64 * dt).collect();
        let v = vec![vm; n];
        let extra = vec![3.0; n];
        let o = CouplingOptions {
            extra: Some(&extra),
            ..Default::default()
        };
        let r = load_coupling(&m, &x, &v, dt, &o).unwrap();
        let want = m.friction.stribeck(vm) + 3.0;
        assert!(
            (r.force[n - 1] - want).abs() < 1e-6 * want,
            "{}",
            r.force[n - 1]
        );
        assert!((r.v[n - 1] - vm).abs() < 1e-9);
    }
}
