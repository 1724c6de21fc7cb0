//! The load behind the compliant coupling of the `resonance` effect, driven by the
//! measured motor motion.
//!
//! With a `resonance`, the encoder measures the motor `(1 - r)*M`; the friction and the
//! other effects act on the load `r*M`, joined to the motor by a spring `k` and a damper
//! `c`. The motor force that the model needs is `(1 - r)*M*a_m + F_s`, where
//! `F_s = k*(x_m - x_l) + c*(v_m - v_l)` is the force the coupling passes to the load.
//! The load's motion `x_l` is not measured: [`load_coupling`] simulates it, driven by the
//! sampled motor position and velocity (linear interpolation between samples), by
//! leapfrog: the velocity lives at the middle of each substep, its values at the start
//! (for the damper and the friction) and at the middle (for the bristles' exact update)
//! are predicted from the last acceleration. Second order while the load slides; first
//! order through reversals, where the friction is not smooth (the servo simulation's
//! semi-implicit Euler step is first order everywhere). The algorithm is fixed in
//! `docs/DESIGN.md` ("Load behind the coupling") and repeated step for step by
//! `lugre.reference.load_coupling`.
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
    /// Further force on the load per sample [N] (cogging, springs, offsets, drag,
    /// gravity evaluated by the caller); `None` for 0.
    pub extra: Option<&'a [f64]>,
    /// Rise of both friction levels of both directions per sample [N], `>= 0` (a
    /// `load_friction`'s `coefficient*|F_m|`, evaluated by the caller); `None` for 0.
    pub level: Option<&'a [f64]>,
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
            level: None,
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
    if let Some(lv) = opts.level {
        check_len("level", lv, x.len(), "x")?;
        check_finite("level", lv)?;
        if let Some(k) = lv.iter().position(|&l| l < 0.0) {
            return Err(Error::input(
                "level",
                format!("element {k} is {}: give levels of zero or more", lv[k]),
            ));
        }
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

/// Load simulations run interleaved in one loop by [`coupling_forces`]: each is a
/// chain of dependent operations (divisions, `exp`) that leaves the processor idle
/// between them, and independent chains fill that time.
pub(crate) const LANES: usize = 4; // (run_lanes has a loop for each width up to it)

/// The coupling forces of several load simulations along one motor motion, as
/// [`coupling_force`] of each `(model, options)` (bit for bit), up to [`LANES`] at a
/// time interleaved in one loop, the loops in parallel (rayon): simulations with the
/// same number of substeps and the same Stribeck shape share a loop. Each loop's
/// forces go to `then` with the indices of their jobs while they are in the cache;
/// `then` returns one result per job of the loop (the forces themselves: `|_, f| f`).
#[cfg(feature = "std")]
pub(crate) fn coupling_forces<T: Send>(
    jobs: &[(&Model, CouplingOptions<'_>)],
    x: &[f64],
    v: &[f64],
    dt: f64,
    then: impl Fn(&[usize], Vec<Result<Vec<f64>>>) -> Vec<Result<T>> + Sync,
) -> Vec<Result<T>> {
    use rayon::prelude::*;
    let mut out: Vec<Option<Result<T>>> = Vec::with_capacity(jobs.len());
    let mut ready: Vec<Ready> = Vec::new();
    for (j, (m, o)) in jobs.iter().enumerate() {
        let checked = Coupling::from_model(m)
            .and_then(|cp| check_inputs(&cp, x, v, dt, o).map(|n_sub| (cp, n_sub)));
        match checked {
            Ok((cp, n_sub)) => {
                ready.push(Ready {
                    n_sub,
                    exponent: cp.exponent.map(f64::to_bits),
                    job: j,
                    cp,
                });
                out.push(None);
            }
            Err(e) => out.push(Some(Err(e))),
        }
    }
    // jobs of one loop side by side (stable: in the order of the jobs), then at most
    // LANES a loop, fewer when that leaves threads idle
    ready.sort_by_key(|r| (r.n_sub, r.exponent));
    let width = ready
        .len()
        .div_ceil(rayon::current_num_threads().max(1))
        .clamp(1, LANES);
    let mut chunks: Vec<&[Ready]> = Vec::new();
    for group in ready.chunk_by(|a, b| (a.n_sub, a.exponent) == (b.n_sub, b.exponent)) {
        chunks.extend(group.chunks(width));
    }
    let done: Vec<(usize, Result<T>)> = chunks
        .par_iter()
        .flat_map_iter(|chunk| {
            let lanes: Vec<(&Coupling, &CouplingOptions)> =
                chunk.iter().map(|r| (&r.cp, &jobs[r.job].1)).collect();
            let idx: Vec<usize> = chunk.iter().map(|r| r.job).collect();
            let forces = run_lanes(&lanes, x, v, dt, chunk[0].n_sub);
            let results = then(&idx, forces);
            assert_eq!(results.len(), idx.len(), "one result per job");
            idx.into_iter().zip(results)
        })
        .collect();
    for (j, f) in done {
        out[j] = Some(f);
    }
    out.into_iter()
        .map(|r| r.expect("every job has a result"))
        .collect()
}

/// A job of [`coupling_forces`] with checked inputs: its loop (substeps, Stribeck
/// exponent), its index and its coupling.
#[cfg(feature = "std")]
struct Ready {
    n_sub: usize,
    exponent: Option<u64>,
    job: usize,
    cp: Coupling,
}

/// [`run`] of up to [`LANES`] loads with `n_sub` substeps and one Stribeck shape,
/// interleaved (no load trajectory kept).
#[cfg(feature = "std")]
fn run_lanes(
    lanes: &[(&Coupling, &CouplingOptions)],
    x: &[f64],
    v: &[f64],
    dt: f64,
    n_sub: usize,
) -> Vec<Result<Vec<f64>>> {
    let exponent = lanes[0].0.exponent;
    macro_rules! width {
        ($shape:expr) => {
            match lanes.len() {
                1 => run_width::<_, 1>($shape, lanes, x, v, dt, n_sub),
                2 => run_width::<_, 2>($shape, lanes, x, v, dt, n_sub),
                3 => run_width::<_, 3>($shape, lanes, x, v, dt, n_sub),
                _ => run_width::<_, 4>($shape, lanes, x, v, dt, n_sub),
            }
        };
    }
    match exponent {
        None => width!(Square),
        Some(e) => width!(Power(e)),
    }
}

/// [`run_lanes`] with `L` lanes.
#[cfg(feature = "std")]
#[inline(always)]
fn run_width<S: Shape, const L: usize>(
    shape: S,
    lanes: &[(&Coupling, &CouplingOptions)],
    x: &[f64],
    v: &[f64],
    dt: f64,
    n_sub: usize,
) -> Vec<Result<Vec<f64>>> {
    assert_eq!(lanes.len(), L, "one lane per simulation");
    let n = x.len();
    let mut force: [Vec<f64>; L] = core::array::from_fn(|_| vec![0.0; n]);
    if n == 0 {
        return force.into_iter().map(Ok).collect();
    }
    let (x, v) = (&x[..n], &v[..n]);
    let op: [&CouplingOptions; L] = core::array::from_fn(|l| lanes[l].1);
    let mut ld: [Load; L] = core::array::from_fn(|l| Load::new(lanes[l].0, op[l].z0, x[0], v[0]));
    let h = dt / n_sub as f64;
    let nf = n_sub as f64;
    let fracs: Vec<f64> = (1..n_sub).map(|j| j as f64 / nf).collect();
    let hh = 0.5 * h;
    let mut bad: [Option<usize>; L] = [None; L];
    for i in 0..n {
        let (x0, v0) = (x[i], v[i]);
        for l in 0..L {
            force[l][i] = ld[l].coupling(x0, v0, hh);
        }
        if i + 1 == n {
            break;
        }
        let s: [f64; L] = core::array::from_fn(|l| op[l].scale.map_or(1.0, |a| a[i]));
        let fe: [f64; L] = core::array::from_fn(|l| op[l].extra.map_or(0.0, |a| a[i]));
        let lv: [Option<f64>; L] = core::array::from_fn(|l| op[l].level.map(|a| a[i]));
        let (dx, dv) = (x[i + 1] - x0, v[i + 1] - v0);
        // the substeps of every lane, side by side
        let mut sub = |xm: f64, vm: f64| {
            for l in 0..L {
                ld[l].step(shape, xm, vm, s[l], lv[l], fe[l], h, hh);
            }
        };
        sub(x0, v0);
        for &f in &fracs {
            sub(x0 + dx * f, v0 + dv * f);
        }
        for l in 0..L {
            if bad[l].is_none() && !ld[l].is_finite() {
                bad[l] = Some(i);
            }
        }
        if bad.iter().all(Option::is_some) {
            break;
        }
    }
    force
        .into_iter()
        .zip(bad)
        .map(|(f, b)| match b {
            None => Ok(f),
            Some(i) => Err(diverged(i)),
        })
        .collect()
}

/// The error of a load that diverged after sample `i`.
fn diverged(i: usize) -> Error {
    Error::Data(format!(
        "the load behind the coupling diverged after sample {i}: check the \
         motor motion and the model's resonance"
    ))
}

/// One load simulation: its coupling and friction, and its state between substeps
/// (position at a substep's start, velocity at the middle of the substep before, that
/// substep's acceleration, bristle deflection). The one step of [`run_shaped`] and of
/// the interleaved lanes of [`run_width`].
struct Load {
    k: f64,
    c: f64,
    ml: f64,
    fr: Fast,
    xl: f64,
    vl: f64,
    al: f64,
    z: f64,
}

impl Load {
    /// At rest against the motor's first sample `(x0, v0)`, bristles at `z0`.
    fn new(cp: &Coupling, z0: f64, x0: f64, v0: f64) -> Load {
        Load {
            k: cp.k,
            c: cp.c,
            ml: cp.ml,
            fr: Fast::new(&cp.friction, cp.exponent),
            xl: x0,
            vl: v0,
            al: 0.0,
            z: z0,
        }
    }

    /// The velocity at a substep's start, predicted from the last acceleration.
    #[inline(always)]
    fn v_start(&self, hh: f64) -> f64 {
        self.vl + hh * self.al
    }

    /// The force the coupling passes to the load with the motor at `(xm, vm)`.
    #[inline(always)]
    fn coupling(&self, xm: f64, vm: f64, hh: f64) -> f64 {
        self.k * (xm - self.xl) + self.c * (vm - self.v_start(hh))
    }

    /// One substep of length `h` (`hh = h/2`) with the motor at `(xm, vm)`, friction
    /// scale `s` and level rise `lv`: the velocities at its start and middle predicted
    /// from the last acceleration (the bristles' update then does not wait for this
    /// substep's acceleration), then leapfrog.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn step<S: Shape>(
        &mut self,
        shape: S,
        xm: f64,
        vm: f64,
        s: f64,
        lv: Option<f64>,
        fe: f64,
        h: f64,
        hh: f64,
    ) {
        let vt = self.v_start(hh);
        let vz = self.vl + h * self.al;
        let fs = self.k * (xm - self.xl) + self.c * (vm - vt);
        let (g, ff) = match lv {
            None => self.fr.eval(shape, self.z, vt, s),
            Some(l) => self.fr.eval_level(shape, self.z, vt, s, l),
        };
        self.al = (fs - ff - fe) / self.ml;
        self.z = self.fr.advance_z(self.z, vz, g, h);
        self.vl += self.al * h;
        self.xl += self.vl * h;
    }

    fn is_finite(&self) -> bool {
        self.xl.is_finite() && self.vl.is_finite() && self.z.is_finite()
    }
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
    match cp.exponent {
        None => run_shaped(cp, Square, x, v, dt, opts, n_sub, force, load),
        Some(e) => run_shaped(cp, Power(e), x, v, dt, opts, n_sub, force, load),
    }
}

/// [`run`] for one shape of the Stribeck curve.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn run_shaped<S: Shape>(
    cp: &Coupling,
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
    let h = dt / n_sub as f64;
    let nf = n_sub as f64;
    // the interpolation fractions j/n of the substeps after the first
    let fracs: Vec<f64> = (1..n_sub).map(|j| j as f64 / nf).collect();
    let hh = 0.5 * h;
    let mut ld = Load::new(cp, opts.z0, x[0], v[0]);
    for i in 0..n {
        let (x0, v0) = (x[i], v[i]);
        force[i] = ld.coupling(x0, v0, hh);
        if let Some((ox, ov, oz)) = load.as_mut() {
            ox[i] = ld.xl;
            ov[i] = ld.v_start(hh);
            oz[i] = ld.z;
        }
        if i + 1 == n {
            break;
        }
        let s = opts.scale.map_or(1.0, |a| a[i]);
        let lv = opts.level.map(|a| a[i]);
        let fe = opts.extra.map_or(0.0, |a| a[i]);
        let (dx, dv) = (x[i + 1] - x0, v[i + 1] - v0);
        ld.step(shape, x0, v0, s, lv, fe, h, hh);
        for &f in &fracs {
            ld.step(shape, x0 + dx * f, v0 + dv * f, s, lv, fe, h, hh);
        }
        if !ld.is_finite() {
            return Err(diverged(i));
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
    fn interleaved_as_one_at_a_time() {
        // eleven loads of three loops (substeps, Stribeck exponent), one of them
        // diverging, one without a resonance, one with an error of its options
        let dt = 1e-3;
        let n = 3000;
        let x: Vec<f64> = (0..n).map(|k| 0.02 * (2.1 * k as f64 * dt).sin()).collect();
        let v: Vec<f64> = (0..n)
            .map(|k| 0.042 * (2.1 * k as f64 * dt).cos())
            .collect();
        let scale: Vec<f64> = (0..n).map(|k| 1.0 + 0.1 * (k as f64 * dt).sin()).collect();
        let extra: Vec<f64> = (0..n).map(|k| (3.0 * k as f64 * dt).cos()).collect();
        let mut models = Vec::new();
        for (j, f) in [8.0, 15.0, 22.0, 31.0, 45.0, 60.0, 400.0]
            .iter()
            .enumerate()
        {
            let mut m = model();
            m.effects[0] = Effect::Resonance {
                frequency_hz: *f,
                damping_ratio: 0.03 + 0.05 * j as f64,
                load_fraction: 0.2 + 0.1 * j as f64,
            };
            if j % 3 == 1 {
                m.effects.push(Effect::StribeckShape { exponent: 1.4 });
            }
            models.push(m);
        }
        // negative damping: the load's swing grows until it overflows
        models[2].effects[0] = Effect::Resonance {
            frequency_hz: 30.0,
            damping_ratio: -20.0,
            load_fraction: 0.5,
        };
        models.push(Model::paper());
        models.push(model());
        models.push(model());
        let plain = CouplingOptions {
            substeps: 4,
            ..Default::default()
        };
        let level: Vec<f64> = (0..n).map(|k| 2.0 * (k as f64 * dt).cos().abs()).collect();
        let shaped = CouplingOptions {
            scale: Some(&scale),
            extra: Some(&extra),
            level: Some(&level),
            z0: 1e-5,
            substeps: 2,
        };
        let wrong = CouplingOptions {
            extra: Some(&extra[1..]),
            ..plain
        };
        let mut opts: Vec<CouplingOptions> = (0..7).map(|j| [plain, shaped][j % 2]).collect();
        opts.extend([plain, wrong, plain]);
        let jobs: Vec<(&Model, CouplingOptions)> = models.iter().zip(opts).collect();
        let all = coupling_forces(&jobs, &x, &v, dt, |_, f| f);
        assert_eq!(all.len(), jobs.len());
        let mut errors = 0;
        for ((m, o), got) in jobs.iter().zip(&all) {
            match (coupling_force(m, &x, &v, dt, o), got) {
                (Ok(a), Ok(b)) => {
                    assert!(a.iter().zip(b).all(|(p, q)| p.to_bits() == q.to_bits()));
                }
                (Err(a), Err(b)) => {
                    assert_eq!(a.to_string(), b.to_string());
                    errors += 1;
                }
                (a, b) => panic!("{a:?} against {b:?}"),
            }
        }
        assert_eq!(errors, 3, "{all:?}");
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
        // both levels raised by 4.5 N (a load_friction): 4.5 N more
        let level = vec![4.5; n];
        let o = CouplingOptions {
            level: Some(&level),
            ..o
        };
        let r = load_coupling(&m, &x, &v, dt, &o).unwrap();
        let want = m.friction.stribeck(vm) + 3.0 + 4.5;
        assert!((r.force[n - 1] - want).abs() < 1e-6 * want);
        let bad = [f64::NAN; 3];
        let o = CouplingOptions {
            level: Some(&bad[..2]),
            ..CouplingOptions::default()
        };
        let e = load_coupling(&m, &x[..3], &v[..3], dt, &o).unwrap_err();
        assert!(
            matches!(&e, Error::Input { name, .. } if name == "level"),
            "{e}"
        );
        let o = CouplingOptions {
            level: Some(&[0.0, -1.0, 0.0]),
            ..o
        };
        let e = load_coupling(&m, &x[..3], &v[..3], dt, &o).unwrap_err();
        assert!(
            matches!(&e, Error::Input { name, .. } if name == "level"),
            "{e}"
        );
    }
}
