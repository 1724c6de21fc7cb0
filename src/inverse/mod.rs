//! Inverse dynamics of a recorded axis: the force a model needs along the measured
//! motion, the residual against the motor force, and its sensitivities to the friction
//! parameters.
//!
//! A [`Record`] holds a recording prepared once (low-passed position, its acceleration,
//! the velocity that drives the bristles, the motor force and the parallel low-pass
//! [`Lowpass`]); every call then takes a [`Model`]. The residual is
//!
//! `r = filt(F_m') - m*a - filt(F_friction + F_effects)`
//!
//! where `F_m'` is the motor force after the model's `delay`, `deadband`,
//! `current_limit`, `current_lag` and `force_ripple`, `F_friction` the LuGre force with
//! its bristles advanced over each sample interval with the velocity (and friction
//! scale, and a `load_friction`'s rise of the levels under `F_m'`) at its middle, and
//! `filt` the zero-phase low-pass applied to the position. With a `resonance` the motor carries
//! `(1 - r)*m*a` plus the force its coupling passes to the load, the load simulated
//! along the measured motion ([`crate::servo::load_coupling`]).
//!
//! The algorithm is fixed in `docs/DESIGN.md` ("Inverse dynamics") and repeated step for
//! step by the NumPy twin `lugre.reference.InverseRecord`.

mod filter;
mod fit;
mod sensitivities;
mod spectrum;

pub use filter::{moving_median, Lanes, Lowpass, LANES};
pub use fit::{fit_base, BaseFit, BaseFitOptions, FitParam};
pub use sensitivities::{BaseParam, Sensitivities};
pub use spectrum::{position_sums, PositionSums, MAX_FREQUENCIES, RESEED};

use crate::error::{check_finite, check_len, Error, Result};
use crate::servo::coupling::coupling_forces;
use crate::servo::effects::{drift_factor, Actuator};
use crate::servo::fast::{Fast, Power, Shape, Square};
use crate::servo::{coupling_force, CouplingOptions, Effect, Model};

/// Substeps multiplier of the load simulation behind a `resonance`: twice the automatic
/// number. The truth model's residual on a noise-free record is then within 20 % of
/// the converged one (docs/DIAGNOSIS.md, "Known limits").
pub const COUPLING_SUBSTEPS: usize = 2;

/// Linear interpolation as `numpy.interp` (constant beyond the ends, knots exact).
fn interp_into(x: &[f64], xp: &[f64], fp: &[f64], out: &mut [f64]) {
    let m = xp.len();
    for (o, &xv) in out.iter_mut().zip(x) {
        *o = if xv < xp[0] {
            fp[0]
        } else if xv >= xp[m - 1] {
            fp[m - 1]
        } else {
            // largest j with xp[j] <= xv
            let j = xp.partition_point(|&p| p <= xv) - 1;
            if xp[j] == xv {
                fp[j]
            } else {
                let slope = (fp[j + 1] - fp[j]) / (xp[j + 1] - xp[j]);
                slope * (xv - xp[j]) + fp[j]
            }
        };
    }
}

/// A recording prepared for inverse dynamics (all arrays of one length).
#[derive(Debug, Clone, PartialEq)]
pub struct Record {
    dt: f64,
    t: Vec<f64>,
    x: Vec<f64>,
    x_drive: Vec<f64>,
    v: Vec<f64>,
    a: Vec<f64>,
    fm: Vec<f64>,
    fm_f: Vec<f64>,
    filter: Lowpass,
}

impl Record {
    /// A record from its prepared signals.
    ///
    /// `t`: time from the origin of time-dependent effects [s]; `x`: low-passed position
    /// [m]; `x_drive`, `v`: lightly filtered position and the velocity that drives the
    /// bristles; `a`: acceleration of `x`; `fm`: motor force [N]; `fm_f`: `fm` filtered;
    /// `dt`: sample interval [s]; `filter`: the parallel low-pass.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        t: Vec<f64>,
        x: Vec<f64>,
        x_drive: Vec<f64>,
        v: Vec<f64>,
        a: Vec<f64>,
        fm: Vec<f64>,
        fm_f: Vec<f64>,
        dt: f64,
        filter: Lowpass,
    ) -> Result<Record> {
        let n = t.len();
        if n < 2 {
            return Err(Error::input("t", "needs at least two samples"));
        }
        for (name, a) in [
            ("t", &t),
            ("x", &x),
            ("x_drive", &x_drive),
            ("v", &v),
            ("a", &a),
            ("fm", &fm),
            ("fm_f", &fm_f),
        ] {
            check_len(name, a, n, "t")?;
            check_finite(name, a)?;
        }
        if !(dt.is_finite() && dt > 0.0) {
            return Err(Error::parameter(
                "dt",
                dt,
                "must be a finite sample interval greater than zero [s]",
            ));
        }
        Ok(Record {
            dt,
            t,
            x,
            x_drive,
            v,
            a,
            fm,
            fm_f,
            filter,
        })
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.t.len()
    }

    /// Never empty (at least two samples).
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    /// The parallel low-pass of a signal of the record's length.
    pub fn filt(&self, y: &[f64]) -> Vec<f64> {
        self.filter.filtfilt(y)
    }

    /// [`Lowpass::filtfilt_lanes`] of up to [`LANES`] signals of the record's length,
    /// sample `k` of signal `l` read as `y(l, k)`.
    pub fn filt_lanes(&self, width: usize, y: impl Fn(usize, usize) -> f64) -> Lanes {
        self.filter.filtfilt_lanes(self.len(), width, y)
    }

    /// [`Record::filt`] of several signals of the record's length, side by side
    /// ([`Lowpass::filtfilt_many`]) and in parallel (rayon).
    pub fn filt_many(&self, ys: &[Vec<f64>]) -> Vec<Vec<f64>> {
        use rayon::prelude::*;
        ys.par_chunks(LANES)
            .flat_map_iter(|chunk| {
                let refs: Vec<&[f64]> = chunk.iter().map(Vec::as_slice).collect();
                self.filter.filtfilt_many(&refs)
            })
            .collect()
    }

    /// [`Record::filt_many`] in place: each signal replaced by its low-pass.
    pub fn filt_in_place(&self, ys: &mut [Vec<f64>]) {
        use rayon::prelude::*;
        ys.par_chunks_mut(LANES).for_each(|chunk| {
            let f = self.filt_lanes(chunk.len(), |l, k| chunk[l][k]);
            for (l, y) in chunk.iter_mut().enumerate() {
                y.iter_mut().zip(f.lane(l)).for_each(|(y, v)| *y = v);
            }
        });
    }

    /// Product of the `position_friction` and `drift` scales, in the order of the
    /// effects, or `None` without them.
    pub fn friction_scale(&self, model: &Model) -> Option<Vec<f64>> {
        let n = self.len();
        let mut s: Option<Vec<f64>> = None;
        let mut f = vec![0.0; n];
        for e in &model.effects {
            match e {
                Effect::PositionFriction { positions, scale } => {
                    interp_into(&self.x, positions, scale, &mut f);
                }
                Effect::Drift {
                    gain,
                    time_constant,
                } => {
                    for (o, &t) in f.iter_mut().zip(&self.t) {
                        *o = drift_factor(*gain, *time_constant, t);
                    }
                }
                _ => continue,
            }
            match s.as_mut() {
                None => s = Some(f.clone()),
                Some(acc) => acc.iter_mut().zip(&f).for_each(|(a, b)| *a *= b),
            }
        }
        s
    }

    /// The rise `coefficient*|F_m'|` [N] of the friction levels at the samples under a
    /// `load_friction`, `F_m'` the unfiltered motor force after the actuator
    /// ([`Record::actuator_force`], else the recorded one); `None` without one.
    pub fn friction_level(&self, model: &Model) -> Option<Vec<f64>> {
        let act = Actuator::new(&model.effects);
        act.load?;
        let f = self.actuator_force(model);
        let f = f.as_deref().unwrap_or(&self.fm);
        Some(f.iter().map(|&y| act.level(y)).collect())
    }

    /// Unfiltered LuGre force at the samples (position/drift scales, the rise of a
    /// `load_friction` and the Stribeck exponent of the model included).
    pub fn base_friction(&self, model: &Model) -> Vec<f64> {
        let exponent = exponent_of(model);
        let s = self.friction_scale(model);
        let level = self.friction_level(model);
        let fr = Fast::new(&model.friction, exponent);
        let (s, l) = (s.as_deref(), level.as_deref());
        match (exponent, l) {
            (None, None) => self.lugre_force::<_, false>(&fr, Square, s, &[]),
            (None, Some(l)) => self.lugre_force::<_, true>(&fr, Square, s, l),
            (Some(e), None) => self.lugre_force::<_, false>(&fr, Power(e), s, &[]),
            (Some(e), Some(l)) => self.lugre_force::<_, true>(&fr, Power(e), s, l),
        }
    }

    /// The force at each sample `k` at `(z_k, v[k])` with `s[k]` (and the levels raised
    /// by `level[k]` when `LOADED`); then `z` advanced over the interval with the
    /// velocity, scale and level at its middle.
    fn lugre_force<S: Shape, const LOADED: bool>(
        &self,
        fr: &Fast,
        shape: S,
        s: Option<&[f64]>,
        level: &[f64],
    ) -> Vec<f64> {
        let n = self.len();
        let v = &self.v[..n];
        let s = s.map(|s| &s[..n]);
        let level = if LOADED { &level[..n] } else { level };
        let mut out = vec![0.0; n];
        let mut z = 0.0;
        for k in 0..n {
            let sc = s.map_or(1.0, |s| s[k]);
            out[k] = if LOADED {
                fr.eval_level(shape, z, v[k], sc, level[k]).1
            } else {
                fr.eval(shape, z, v[k], sc).1
            };
            if k + 1 < n {
                let u = 0.5 * (v[k] + v[k + 1]);
                let su = s.map_or(1.0, |s| 0.5 * (s[k] + s[k + 1]));
                let g = if LOADED {
                    fr.g_level(shape, u, su, 0.5 * (level[k] + level[k + 1]))
                } else {
                    fr.g(shape, u, su)
                };
                z = fr.advance_z(z, u, g, self.dt);
            }
        }
        out
    }

    /// Unfiltered sum of the effect forces (cogging, spring, offset, drag, gravity) at
    /// the samples, added effect by effect in the order of the model
    /// ([`Effect::add_force`]).
    pub fn effect_force(&self, model: &Model) -> Vec<f64> {
        let forces: Vec<&Effect> = model.effects.iter().filter(|e| e.is_force()).collect();
        self.x
            .iter()
            .zip(&self.v)
            .map(|(&x, &v)| forces.iter().fold(0.0, |f, e| e.add_force(f, x, v)))
            .collect()
    }

    /// Unfiltered force the `resonance` coupling passes to the load, the load simulated
    /// along the drive motion with its friction, the friction scales, the rise of the
    /// levels of a `load_friction` and the effect forces on it.
    pub fn coupling_force(&self, model: &Model) -> Result<Vec<f64>> {
        let load = self.load_forces(model);
        coupling_force(
            model,
            &self.x_drive,
            &self.v,
            self.dt,
            &self.coupling_options(&load),
        )
    }

    /// The friction scale, the effect forces and the rise of the friction levels on
    /// the load of a `resonance`.
    fn load_forces(&self, model: &Model) -> LoadForces {
        // (no force effect: none, the same numbers as zeros at a fraction of the memory)
        let forces = model.effects.iter().any(Effect::is_force);
        LoadForces {
            scale: self.friction_scale(model),
            extra: forces.then(|| self.effect_force(model)),
            level: self.friction_level(model),
        }
    }

    /// The options of the load simulation of [`Record::coupling_force`].
    fn coupling_options<'a>(&self, load: &'a LoadForces) -> CouplingOptions<'a> {
        CouplingOptions {
            scale: load.scale.as_deref(),
            extra: load.extra.as_deref(),
            level: load.level.as_deref(),
            z0: 0.0,
            substeps: COUPLING_SUBSTEPS,
        }
    }

    /// The `load_fraction` of the model's `resonance`, if it has one.
    fn load_fraction(model: &Model) -> Option<f64> {
        model.effects.iter().find_map(|e| match e {
            Effect::Resonance { load_fraction, .. } => Some(*load_fraction),
            _ => None,
        })
    }

    /// Filtered force the model needs besides the motor: `m*a + F_friction + F_effects`
    /// (with a `resonance`: `(1 - r)*m*a + F_coupling`).
    pub fn model_force(&self, model: &Model) -> Result<Vec<f64>> {
        let coupling = match Self::load_fraction(model) {
            None => None,
            Some(_) => Some(self.coupling_force(model)?),
        };
        Ok(self.model_force_with(model, coupling))
    }

    /// [`Record::model_force`] with the unfiltered coupling force of a model with a
    /// `resonance` given.
    fn model_force_with(&self, model: &Model, coupling: Option<Vec<f64>>) -> Vec<f64> {
        let (ma, f) = self.model_force_raw(model, coupling);
        self.add_inertia(ma, &self.filt(&f))
    }

    /// The mass that the measured acceleration moves and the unfiltered force the model
    /// needs besides it: `(m, F_friction + F_effects)`, with a `resonance` (its
    /// coupling force given) `((1 - r)*m, F_coupling)`.
    fn model_force_raw(&self, model: &Model, coupling: Option<Vec<f64>>) -> (f64, Vec<f64>) {
        let m = model.total_mass();
        match (Self::load_fraction(model), coupling) {
            (Some(r), Some(fc)) => ((1.0 - r) * m, fc),
            _ => {
                let mut f = self.base_friction(model);
                let e = self.effect_force(model);
                f.iter_mut().zip(&e).for_each(|(a, b)| *a += b);
                (m, f)
            }
        }
    }

    /// `ma*a + f`.
    fn add_inertia(&self, ma: f64, f: &[f64]) -> Vec<f64> {
        self.a.iter().zip(f).map(|(a, f)| ma * a + f).collect()
    }

    /// Filtered motor force after the model's actuator ([`Record::actuator_force`]);
    /// the prepared `filt(F_m)` when the model changes nothing.
    pub fn motor_force(&self, model: &Model) -> Vec<f64> {
        match self.actuator_force(model) {
            None => self.fm_f.clone(),
            Some(f) => self.filt(&f),
        }
    }

    /// Unfiltered motor force after the model's `delay` (`numpy.interp` at `t - d`),
    /// `deadband` (`sign(f)*max(|f| - K_F*c, 0)`), `current_limit` (clipped to
    /// `+-K_F*current`), `current_lag` ([`lag_foh`]) and `force_ripple` (times
    /// `1 + sum A*sin(2*pi*x/pitch + phase)` at the low-passed position), in this order;
    /// `None` when the model has none of them.
    pub fn actuator_force(&self, model: &Model) -> Option<Vec<f64>> {
        let kf = model.axis.force_constant;
        let act = Actuator::new(&model.effects);
        let mut delay = None;
        let mut lag = None;
        for e in &model.effects {
            match e {
                Effect::Delay { seconds } if *seconds > 0.0 => delay = Some(*seconds),
                Effect::CurrentLag { bandwidth_hz } => lag = Some(*bandwidth_hz),
                _ => {}
            }
        }
        let band = act.deadband.filter(|&c| c > 0.0).map(|c| c * kf);
        let limit = act.limit.map(|c| c * kf);
        let none = [delay, band, limit, lag].iter().all(Option::is_none);
        if none && act.ripple.is_empty() {
            return None;
        }
        let mut f = self.fm.clone();
        if let Some(d) = delay {
            let ts: Vec<f64> = self.t.iter().map(|t| t - d).collect();
            interp_into(&ts, &self.t, &self.fm, &mut f);
        }
        if let Some(b) = band {
            f.iter_mut().for_each(|y| *y = deadband(*y, b));
        }
        if let Some(l) = limit {
            f.iter_mut().for_each(|y| *y = y.clamp(-l, l));
        }
        if let Some(bw) = lag {
            lag_foh(&mut f, bw, self.dt);
        }
        if !act.ripple.is_empty() {
            for (y, &x) in f.iter_mut().zip(&self.x) {
                *y = act.ripple(*y, x);
            }
        }
        Some(f)
    }

    /// Force residual `filt(F_m') - m*a - filt(F_friction + F_effects)` [N].
    pub fn residual(&self, model: &Model) -> Result<Vec<f64>> {
        let mut r = self.motor_force(model);
        let f = self.model_force(model)?;
        r.iter_mut().zip(&f).for_each(|(a, b)| *a -= b);
        Ok(r)
    }

    /// [`Record::residual`] of several models, in parallel (rayon); the first error
    /// in the order of `models` when any fails. The load simulations of the models
    /// with a `resonance` run interleaved, several in one loop
    /// ([`crate::servo::coupling::LANES`]), and so do their low-passes
    /// ([`Lowpass::filtfilt_many`]); the results are those of one at a time.
    pub fn residuals(&self, models: &[Model]) -> Result<Vec<Vec<f64>>> {
        use rayon::prelude::*;
        let (coupled, plain): (Vec<usize>, Vec<usize>) =
            (0..models.len()).partition(|&j| Self::load_fraction(&models[j]).is_some());
        let mut out: Vec<Option<Result<Vec<f64>>>> = (0..models.len()).map(|_| None).collect();
        // the models with a resonance: their load simulations side by side, then (in
        // the cache) the low-passes of those forces side by side
        let loads: Vec<LoadForces> = coupled
            .par_iter()
            .map(|&j| self.load_forces(&models[j]))
            .collect();
        let jobs: Vec<(&Model, CouplingOptions)> = coupled
            .iter()
            .zip(&loads)
            .map(|(&j, load)| (&models[j], self.coupling_options(load)))
            .collect();
        let done = coupling_forces(&jobs, &self.x_drive, &self.v, self.dt, |idx, forces| {
            let ms: Vec<&Model> = idx.iter().map(|&i| &models[coupled[i]]).collect();
            let mut raw = Vec::with_capacity(idx.len());
            let mut errors = Vec::new();
            for (k, f) in forces.into_iter().enumerate() {
                match f {
                    Ok(fc) => raw.push((k, self.model_force_raw(ms[k], Some(fc)))),
                    Err(e) => errors.push((k, e)),
                }
            }
            let mut res: Vec<Option<Result<Vec<f64>>>> = (0..idx.len()).map(|_| None).collect();
            for (k, r) in self.finish(&ms, raw) {
                res[k] = Some(Ok(r));
            }
            for (k, e) in errors {
                res[k] = Some(Err(e));
            }
            res.into_iter().map(|r| r.expect("one result")).collect()
        });
        for (&j, r) in coupled.iter().zip(done) {
            out[j] = Some(r);
        }
        // the others: friction and effect forces, low-passed side by side, in chunks
        // small enough to keep every thread busy (a batch of four on two threads ran on
        // one)
        let lanes = LANES
            .min(plain.len().div_ceil(rayon::current_num_threads().max(1)))
            .max(1);
        let done: Vec<(usize, Vec<f64>)> = plain
            .par_chunks(lanes)
            .flat_map_iter(|chunk| {
                let ms: Vec<&Model> = chunk.iter().map(|&j| &models[j]).collect();
                let raw = (0..chunk.len())
                    .map(|k| (k, self.model_force_raw(ms[k], None)))
                    .collect();
                self.finish(&ms, raw)
                    .into_iter()
                    .map(|(k, r)| (chunk[k], r))
            })
            .collect();
        for (j, r) in done {
            out[j] = Some(Ok(r));
        }
        out.into_iter()
            .map(|r| r.expect("every model has a residual"))
            .collect()
    }

    /// The residuals of models (`ms[k]`) from their unfiltered model forces
    /// ([`Record::model_force_raw`], by index `k`), the low-passes side by side, each
    /// residual written over its model force (no copy of the record's length more).
    fn finish(
        &self,
        ms: &[&Model],
        mut raw: Vec<(usize, (f64, Vec<f64>))>,
    ) -> Vec<(usize, Vec<f64>)> {
        for chunk in raw.chunks_mut(LANES) {
            let filtered = self.filt_lanes(chunk.len(), |l, i| chunk[l].1 .1[i]);
            for (l, (k, (ma, y))) in chunk.iter_mut().enumerate() {
                // motor force minus what the model needs, `ma*a + f`
                let motor = self.actuator_force(ms[*k]).map(|f| self.filt(&f));
                let motor = motor.as_deref().unwrap_or(&self.fm_f);
                for (i, ((r, m), a)) in y.iter_mut().zip(motor).zip(&self.a).enumerate() {
                    *r = m - (*ma * a + filtered.get(l, i));
                }
            }
        }
        raw.into_iter().map(|(k, (_, r))| (k, r)).collect()
    }
}

/// What acts on the load of a `resonance` besides the coupling, per sample.
struct LoadForces {
    /// The friction scale (`None`: 1).
    scale: Option<Vec<f64>>,
    /// The effect forces [N] (`None`: no force effect).
    extra: Option<Vec<f64>>,
    /// The rise of the friction levels (`None`: 0).
    level: Option<Vec<f64>>,
}

/// The model's Stribeck exponent when it is not 2.
fn exponent_of(model: &Model) -> Option<f64> {
    model.stribeck_exponent().filter(|&e| e != 2.0)
}

/// `sign(f)*max(|f| - band, 0)`.
#[inline]
pub fn deadband(f: f64, band: f64) -> f64 {
    let m = (f.abs() - band).max(0.0);
    if f > 0.0 {
        m
    } else if f < 0.0 {
        -m
    } else {
        0.0
    }
}

/// First-order lag, in place, of a signal interpolated linearly between its samples
/// (exact): `y[n] = c*y[n-1] + b1*f[n] + (1 - c - b1)*f[n-1]`, `a = 2*pi*bw*dt`,
/// `c = exp(-a)`, `b1 = 1 - (1 - c)/a`, started at rest at `f[0]`.
pub fn lag_foh(f: &mut [f64], bandwidth_hz: f64, dt: f64) {
    let a = 2.0 * core::f64::consts::PI * bandwidth_hz * dt;
    let c = (-a).exp();
    let b1 = 1.0 - (1.0 - c) / a;
    let b2 = 1.0 - c - b1;
    if f.is_empty() {
        return;
    }
    let mut state = (1.0 - b1) * f[0];
    for y in f.iter_mut() {
        let x = *y;
        let out = b1 * x + state;
        state = b2 * x + c * out;
        *y = out;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::friction::{LugreParams, StaticSet};

    fn record(n: usize) -> Record {
        let dt = 1e-3;
        let t: Vec<f64> = (0..n).map(|k| k as f64 * dt).collect();
        let x: Vec<f64> = t.iter().map(|t| 0.02 * (2.0 * t).sin()).collect();
        let v: Vec<f64> = t.iter().map(|t| 0.04 * (2.0 * t).cos()).collect();
        let a: Vec<f64> = t.iter().map(|t| -0.08 * (2.0 * t).sin()).collect();
        let fm: Vec<f64> = v.iter().map(|v| 40.0 * v.signum() + 300.0 * v).collect();
        Record::new(
            t,
            x.clone(),
            x,
            v,
            a,
            fm.clone(),
            fm,
            dt,
            Lowpass::identity(),
        )
        .unwrap()
    }

    fn side(fr: &mut LugreParams<f64>, pos: bool) -> &mut StaticSet<f64> {
        if pos {
            &mut fr.positive
        } else {
            &mut fr.negative
        }
    }

    fn bump(x: &mut f64, h: f64) -> f64 {
        *x += h;
        h
    }

    #[test]
    fn sensitivities_match_differences() {
        let mut m = Model::paper();
        m.friction.sigma0 = 2e3; // slow bristles: presliding visible at 1 kHz
        sensitivities_of(&m);
        // the levels raised under the motor force, after a dead band and a ripple
        m.effects = vec![
            Effect::LoadFriction { coefficient: 0.2 },
            Effect::ForceRipple {
                amplitude: 0.1,
                pitch: 0.013,
                phase: 0.0,
            },
            Effect::Deadband { current: 0.3 },
        ];
        sensitivities_of(&m);
    }

    /// The columns of [`Record::base_sensitivities`] against forward differences.
    fn sensitivities_of(m: &Model) {
        let rec = record(3000);
        let names = [
            "positive.fc",
            "positive.fs",
            "positive.sigma2",
            "positive.vs",
            "negative.fc",
            "negative.fs",
            "negative.sigma2",
            "negative.vs",
            "sigma0",
            "sigma1",
        ];
        let params: Vec<BaseParam> = names.iter().map(|n| BaseParam::parse(n).unwrap()).collect();
        let sens = rec.base_sensitivities(m, &params);
        let f0 = rec.base_friction(m);
        for (a, b) in sens.force.iter().zip(&f0) {
            assert_eq!(a, b);
        }
        for (j, name) in names.iter().enumerate() {
            let mut m2 = m.clone();
            let fr = &mut m2.friction;
            let h = match params[j] {
                BaseParam::Fc(p) => bump(&mut side(fr, p).fc, 1e-6),
                BaseParam::Fs(p) => bump(&mut side(fr, p).fs, 1e-6),
                BaseParam::Sigma2(p) => bump(&mut side(fr, p).sigma2, 1e-5),
                BaseParam::Vs(p) => bump(&mut side(fr, p).vs, 1e-9),
                BaseParam::Sigma0 => bump(&mut fr.sigma0, 1e-3),
                BaseParam::Sigma1 => bump(&mut fr.sigma1, 1e-5),
            };
            let f1 = rec.base_friction(&m2);
            let scale = sens.columns[j].iter().fold(0.0f64, |a, b| a.max(b.abs()));
            assert!(scale > 0.0, "{name}");
            for k in 0..f0.len() {
                let fd = (f1[k] - f0[k]) / h;
                assert!(
                    (fd - sens.columns[j][k]).abs() < 1e-4 * scale,
                    "{name} at {k}: {fd} vs {}",
                    sens.columns[j][k]
                );
            }
        }
    }

    #[test]
    fn residual_zero_for_matching_force() {
        let rec = record(500);
        let m = Model::paper();
        // a motor force equal to the model's force leaves no residual
        let need = rec.model_force(&m).unwrap();
        let rec2 = Record::new(
            rec.t.clone(),
            rec.x.clone(),
            rec.x_drive.clone(),
            rec.v.clone(),
            rec.a.clone(),
            need.clone(),
            need,
            rec.dt,
            Lowpass::identity(),
        )
        .unwrap();
        let r = rec2.residual(&m).unwrap();
        assert!(r.iter().all(|x| x.abs() < 1e-9));
    }

    #[test]
    fn residuals_in_parallel_as_one_by_one() {
        let rec = record(800);
        let mut models = vec![Model::paper(); 3];
        models[1].effects.push(Effect::Offset { force: 3.0 });
        models[2].effects.push(Effect::Resonance {
            frequency_hz: 20.0,
            damping_ratio: 0.05,
            load_fraction: 0.5,
        });
        let all = rec.residuals(&models).unwrap();
        for (m, r) in models.iter().zip(&all) {
            assert_eq!(&rec.residual(m).unwrap(), r);
        }
        // more plain models than lanes: chunks sized to the threads, the same numbers
        let many: Vec<Model> = (0..7)
            .map(|k| {
                let mut m = Model::paper();
                m.effects.push(Effect::Offset { force: k as f64 });
                m
            })
            .collect();
        let all = rec.residuals(&many).unwrap();
        for (m, r) in many.iter().zip(&all) {
            assert_eq!(&rec.residual(m).unwrap(), r);
        }
    }

    #[test]
    fn the_actuator_in_its_order_and_the_levels_it_raises() {
        let rec = record(600);
        let kf = Model::paper().axis.force_constant;
        let mut m = Model::paper();
        assert_eq!(rec.actuator_force(&m), None);
        assert_eq!(rec.friction_level(&m), None);
        assert_eq!(rec.motor_force(&m), rec.fm_f);
        let (a, pitch, phase) = (0.08, 0.011, -0.4);
        m.effects = vec![
            Effect::ForceRipple {
                amplitude: a,
                pitch,
                phase,
            },
            Effect::CurrentLimit { current: 1.8 },
            Effect::Deadband { current: 0.2 },
        ];
        let f = rec.actuator_force(&m).unwrap();
        let w = 2.0 * core::f64::consts::PI / pitch;
        let mut clipped = 0;
        for (k, (&fm, &x)) in rec.fm.iter().zip(&rec.x).enumerate() {
            // the dead band on the force, then the clip, then the ripple at x
            let d = deadband(fm, 0.2 * kf);
            let c = d.clamp(-1.8 * kf, 1.8 * kf);
            clipped += usize::from(c != d);
            let want = c * (1.0 + a * (w * x + phase).sin());
            assert_eq!(f[k].to_bits(), want.to_bits(), "sample {k}");
        }
        assert!(clipped > 0 && clipped < rec.len());
        assert_eq!(rec.motor_force(&m), f);
        assert_eq!(rec.friction_level(&m), None);
        m.effects.push(Effect::LoadFriction { coefficient: 0.1 });
        let level = rec.friction_level(&m).unwrap();
        assert!(level.iter().zip(&f).all(|(l, f)| *l == 0.1 * f.abs()));
        // without an actuator the recorded force raises the levels
        m.effects = vec![Effect::LoadFriction { coefficient: 0.1 }];
        let level = rec.friction_level(&m).unwrap();
        assert!(level.iter().zip(&rec.fm).all(|(l, f)| *l == 0.1 * f.abs()));
        // steady sliding: the LuGre force is the Stribeck force with fc and fs raised
        let lifted = rec.base_friction(&m);
        let mut up = Model::paper();
        let k = 300; // (v = 0.04*cos(0.6): sliding forwards for a while)
        let rise = level[k];
        up.friction.positive.fc += rise;
        up.friction.positive.fs += rise;
        let want = up.friction.stribeck(rec.v[k]);
        assert!(
            (lifted[k] - want).abs() < 1e-3 * want,
            "{} {want}",
            lifted[k]
        );
    }

    #[test]
    fn lag_keeps_a_constant_and_delays_a_ramp() {
        let mut f = vec![2.0; 10];
        lag_foh(&mut f, 50.0, 1e-3);
        assert!(f.iter().all(|y| (y - 2.0).abs() < 1e-12));
        // a ramp lags by 1/(2 pi bw) once settled
        let bw = 100.0;
        let dt = 1e-3;
        let mut r: Vec<f64> = (0..400).map(|k| k as f64 * dt).collect();
        lag_foh(&mut r, bw, dt);
        let lagged = 399.0 * dt - r[399];
        assert!((lagged - 1.0 / (2.0 * core::f64::consts::PI * bw)).abs() < 1e-9);
    }

    #[test]
    fn interp_as_numpy() {
        let xp = [0.0, 1.0, 3.0];
        let fp = [1.0, 2.0, 0.0];
        let mut out = [0.0; 6];
        interp_into(&[-1.0, 0.0, 0.5, 1.0, 2.0, 4.0], &xp, &fp, &mut out);
        assert_eq!(out, [1.0, 1.0, 1.5, 2.0, 1.0, 0.0]);
    }

    #[test]
    fn bad_names_and_lengths() {
        assert!(BaseParam::parse("positive.fx").is_err());
        assert!(BaseParam::parse("mass").is_err());
        let e = Record::new(
            vec![0.0, 1.0],
            vec![0.0],
            vec![0.0, 1.0],
            vec![0.0, 1.0],
            vec![0.0, 1.0],
            vec![0.0, 1.0],
            vec![0.0, 1.0],
            1.0,
            Lowpass::identity(),
        );
        assert!(e.is_err());
    }
}
