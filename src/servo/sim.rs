//! Closed- and open-loop simulation of the servo axis with LuGre friction.
//!
//! The digital controller runs at `rate_hz` and its output is held between updates
//! (zero-order hold); the plant is advanced in substeps between events (control
//! instants and output samples). The default integrator updates the bristle state
//! exactly with the velocity held and the mechanics by semi-implicit Euler: two `exp()`
//! per step, no step-size limit from the bristle stiffness. With a `resonance` effect
//! both bodies (motor and load) advance by semi-implicit Euler, which limits the step
//! against the coupling's mode ([`check_resonance_step`]). RK4 is there for
//! comparison. The algorithm is fixed in `docs/DESIGN.md` and mirrored step for step by
//! `lugre.reference`.

use super::effects::{EffectForces, FrictionScale};
use super::model::{ControlLaw, CurrentLoop, Effect, FeedforwardKind, Model};
use crate::error::{check_finite, check_len, check_time, Error, Result};
use crate::friction::{Compensator, LugreParams};
use std::collections::VecDeque;
use std::f64::consts::PI;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// How often a long simulation calls its `keep_going` callback (for Ctrl-C in Python).
///
/// By time, not by steps: from Python the callback has to take the interpreter lock,
/// which a busy Python thread holds for up to its switch interval (5 ms), so a poll
/// every few milliseconds would halve the speed of a simulation running beside it.
pub const POLL_INTERVAL: Duration = Duration::from_millis(50);

/// Plant steps between two looks at the clock (about 0.3 ms at 15 M steps/s).
const POLL_STEPS: usize = 4096;

/// Largest `sigma0*|v|*h/g` of one RK4 step. The bristle state relaxes at the rate
/// `sigma0*|v|/g`, fast at high speed (1.4e4 1/s at 1.4 m/s against a 10 N Coulomb
/// level on a 1e5 N/m bristle), and classic RK4 is unstable beyond 2.78 of it; a plant
/// step that would exceed this bound at its start is taken in equal pieces under it.
pub const RK4_BRISTLE_LIMIT: f64 = 1.0;

/// Most pieces of one RK4 plant step (a guard against absurd parameters).
const RK4_MAX_PIECES: f64 = 1e4;

/// Plant integrator.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Integrator {
    /// Exact bristle update with v held, semi-implicit Euler for x and v.
    #[default]
    Exact,
    /// Classic RK4 on (x, v, z), a step split where the bristles would make it
    /// unstable ([`RK4_BRISTLE_LIMIT`]).
    Rk4,
}

/// Simulation options.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SimOptions {
    /// Plant integrator.
    pub integrator: Integrator,
    /// Plant substeps per control period (or per sample interval in open loop).
    pub substeps: usize,
    /// Initial bristle state [m].
    pub z0: f64,
    /// Initial position [m]; `None` starts at the reference (or 0).
    pub x0: Option<f64>,
    /// Initial velocity [m/s].
    pub v0: f64,
}

impl Default for SimOptions {
    fn default() -> Self {
        Self {
            integrator: Integrator::Exact,
            substeps: 1,
            z0: 0.0,
            x0: None,
            v0: 0.0,
        }
    }
}

/// What drives the axis.
#[derive(Debug, Clone, Copy)]
pub enum Drive<'a> {
    /// Position reference for a `pid` controller, sampled at `t`.
    Position(&'a [f64]),
    /// Speed reference for a `pi_speed` controller, sampled at `t`.
    Speed(&'a [f64]),
    /// Open loop: current command [A] at `t`, held between samples.
    Current(&'a [f64]),
}

/// Sampled trajectories.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SimResult {
    /// Position [m].
    pub x: Vec<f64>,
    /// Velocity [m/s].
    pub v: Vec<f64>,
    /// Bristle deflection [m].
    pub z: Vec<f64>,
    /// Current [A]: actual current with a current loop, else the command.
    pub i: Vec<f64>,
    /// LuGre friction force [N].
    pub friction: Vec<f64>,
    /// Motor force acting on the mass [N].
    pub force: Vec<f64>,
}

/// `np.interp` with a forward-moving cursor (queries must not decrease).
struct Interp<'a> {
    t: &'a [f64],
    y: &'a [f64],
    j: usize,
}

impl<'a> Interp<'a> {
    #[inline(always)]
    fn at(&mut self, tq: f64) -> f64 {
        let n = self.t.len();
        if tq <= self.t[0] {
            return self.y[0];
        }
        if tq >= self.t[n - 1] {
            return self.y[n - 1];
        }
        // tq inside (t[0], t[n-1]): the cursor stops before the last sample
        while self.t[self.j + 1] <= tq {
            self.j += 1;
        }
        let (t0, t1) = (self.t[self.j], self.t[self.j + 1]);
        if tq == t0 {
            return self.y[self.j];
        }
        let y0 = self.y[self.j];
        y0 + (self.y[self.j + 1] - y0) * (tq - t0) / (t1 - t0)
    }
}

/// Extra physics, flattened for the inner loop.
///
/// `EXTRAS = false` is the plain axis (no current loop, current lag, delay, cogging,
/// scaled friction, resonance, dead band, drag or Stribeck shape; springs and offsets
/// are kept): the simulation loop is compiled once
/// for it, with every test of the absent physics removed, and once for the general case.
/// Both run the same code, so their results are identical.
struct Physics<const EXTRAS: bool> {
    mass: f64,
    kf: f64,
    fr: LugreParams<f64>,
    /// Cogging, springs, offsets and drag.
    forces: EffectForces,
    /// `position_friction` and `drift`.
    scales: FrictionScale,
    current_loop: Option<CurrentLoop>,
    lag_w: Option<f64>,
    delay: Option<f64>,
    t0: f64,
    /// `stribeck_shape` exponent.
    shape: Option<f64>,
    /// `deadband` half-width [A].
    deadband: Option<f64>,
    /// Two-mass `resonance`.
    res: Option<TwoMass>,
}

/// The two bodies of the `resonance` effect and their coupling.
#[derive(Debug, Clone, Copy)]
pub(crate) struct TwoMass {
    /// Coupling stiffness [N/m].
    pub(crate) k: f64,
    /// Coupling damping [N s/m].
    pub(crate) c: f64,
    /// Motor-side mass `(1 - r)*M` [kg].
    pub(crate) mm: f64,
    /// Load-side mass `r*M` [kg].
    pub(crate) ml: f64,
}

impl TwoMass {
    pub(crate) fn new(mass: f64, frequency_hz: f64, damping_ratio: f64, r: f64) -> Self {
        let mm = (1.0 - r) * mass;
        let ml = r * mass;
        let w = 2.0 * PI * frequency_hz;
        let k = ml * (w * w);
        let c = 2.0 * damping_ratio * (k * ml).sqrt();
        TwoMass { k, c, mm, ml }
    }

    /// Angular frequency [rad/s] and damping ratio of the free motor-load mode (the
    /// relative motion, reduced mass `mm*ml/(mm + ml)`).
    fn free_mode(&self) -> (f64, f64) {
        let mu = self.mm * self.ml / (self.mm + self.ml);
        let w = (self.k / mu).sqrt();
        (w, self.c / (2.0 * mu * w))
    }
}

/// True when the model needs none of the extras of [`Physics`].
fn is_plain(m: &Model) -> bool {
    m.axis.current_loop.is_none()
        && m.effects.iter().all(|e| {
            matches!(
                e,
                Effect::Spring { .. } | Effect::Offset { .. } | Effect::Mass { .. }
            )
        })
}

impl<const EXTRAS: bool> Physics<EXTRAS> {
    fn new(m: &Model, t0: f64) -> Self {
        debug_assert!(EXTRAS || is_plain(m));
        let mut p = Physics {
            mass: m.total_mass(),
            kf: m.axis.force_constant,
            fr: m.friction,
            forces: EffectForces::new(&m.effects),
            scales: FrictionScale::new(&m.effects),
            current_loop: m.axis.current_loop.clone(),
            lag_w: None,
            delay: None,
            t0,
            shape: None,
            deadband: None,
            res: None,
        };
        for e in &m.effects {
            match e {
                Effect::Delay { seconds } => p.delay = Some(*seconds),
                Effect::CurrentLag { bandwidth_hz } => p.lag_w = Some(2.0 * PI * bandwidth_hz),
                Effect::Resonance {
                    frequency_hz,
                    damping_ratio,
                    load_fraction,
                } => {
                    p.res = Some(TwoMass::new(
                        p.mass,
                        *frequency_hz,
                        *damping_ratio,
                        *load_fraction,
                    ))
                }
                Effect::Deadband { current } => p.deadband = Some(*current),
                Effect::StribeckShape { exponent } => p.shape = Some(*exponent),
                // forces and friction scales: `forces`, `scales`; mass: `total_mass`
                Effect::Cogging { .. }
                | Effect::Spring { .. }
                | Effect::Offset { .. }
                | Effect::PositionFriction { .. }
                | Effect::Drift { .. }
                | Effect::Drag { .. }
                | Effect::Mass { .. } => {}
            }
        }
        p
    }

    #[inline(always)]
    fn current_loop(&self) -> Option<&CurrentLoop> {
        if EXTRAS {
            self.current_loop.as_ref()
        } else {
            None
        }
    }

    #[inline(always)]
    fn lag_w(&self) -> Option<f64> {
        if EXTRAS {
            self.lag_w
        } else {
            None
        }
    }

    #[inline(always)]
    fn delay(&self) -> Option<f64> {
        if EXTRAS {
            self.delay
        } else {
            None
        }
    }

    #[inline(always)]
    fn scale(&self, x: f64, time: f64) -> f64 {
        if !EXTRAS || self.scales.is_empty() {
            return 1.0;
        }
        self.scales.at(x, time - self.t0)
    }

    #[inline(always)]
    fn res(&self) -> Option<&TwoMass> {
        if EXTRAS {
            self.res.as_ref()
        } else {
            None
        }
    }

    /// Position and velocity of the body that carries the friction and the effects:
    /// the load with a `resonance`, else the one rigid body.
    #[inline(always)]
    fn load(&self, s: &State) -> (f64, f64) {
        if self.res().is_some() {
            (s.xl, s.vl)
        } else {
            (s.x, s.v)
        }
    }

    /// `(g, F, zdot)` of the plant's friction (generalised Stribeck curve with a
    /// `stribeck_shape`).
    #[inline(always)]
    fn friction(&self, z: f64, v: f64, scale: f64) -> (f64, f64, f64) {
        if EXTRAS {
            if let Some(e) = self.shape {
                return self.fr.eval_shaped(z, v, scale, e);
            }
        }
        self.fr.eval(z, v, scale)
    }

    /// The current that produces force: the `deadband` removes `current` from `|i|`.
    #[inline(always)]
    fn deadband(&self, i: f64) -> f64 {
        if EXTRAS {
            if let Some(c) = self.deadband {
                return if i > c {
                    i - c
                } else if i < -c {
                    i + c
                } else {
                    0.0
                };
            }
        }
        i
    }

    #[inline(always)]
    fn effect_force(&self, x: f64, v: f64) -> f64 {
        let f = self.forces.linear(x);
        if EXTRAS {
            self.forces.add_nonlinear(f, x, v)
        } else {
            f
        }
    }

    #[inline(always)]
    fn accel(&self, fm: f64, x: f64, v: f64, z: f64, time: f64) -> (f64, f64, f64) {
        let s = self.scale(x, time);
        let (g, f, zdot) = self.friction(z, v, s);
        ((fm - f - self.effect_force(x, v)) / self.mass, g, zdot)
    }
}

#[derive(Debug, Clone, Copy)]
struct State {
    x: f64,
    v: f64,
    z: f64,
    ia: f64,
    q: f64,
    fl: f64,
    /// Load position and velocity (`resonance`; unused without it).
    xl: f64,
    vl: f64,
}

/// The factors of the motor update that depend only on the step length `h`, computed
/// once per interval between events rather than once per plant step (and only for the
/// physics the model has: the compiler would otherwise hoist every `exp()` of
/// [`Physics::motor`] out of the step loop and run them all at each event).
#[derive(Debug, Clone, Copy)]
struct MotorStep {
    h: f64,
    /// `exp(-2*pi*f*h)` of a first-order current loop.
    current_decay: f64,
    /// RK4 sub-steps of an R-L current loop.
    rl_substeps: usize,
    /// `exp(-2*pi*bw*h)` of the `current_lag` effect.
    lag_decay: f64,
}

impl<const EXTRAS: bool> Physics<EXTRAS> {
    fn motor_step(&self, h: f64) -> MotorStep {
        let mut ms = MotorStep {
            h,
            current_decay: 0.0,
            rl_substeps: 1,
            lag_decay: 0.0,
        };
        match self.current_loop() {
            None => {}
            Some(CurrentLoop::FirstOrder { bandwidth_hz }) => {
                ms.current_decay = (-2.0 * PI * bandwidth_hz * h).exp();
            }
            Some(CurrentLoop::Rl { inductance, kp, .. }) => {
                let wc = kp / inductance;
                ms.rl_substeps = ((h * wc * 4.0).ceil() as usize).max(1);
            }
        }
        if let Some(w) = self.lag_w() {
            ms.lag_decay = (-w * h).exp();
        }
        ms
    }

    /// Advance the current (loop) and the lagged force over h; returns the motor force.
    #[inline(always)]
    fn motor(&self, s: &mut State, ic: f64, ms: &MotorStep) -> f64 {
        match self.current_loop() {
            None => s.ia = ic,
            Some(CurrentLoop::FirstOrder { .. }) => {
                s.ia = ic + (s.ia - ic) * ms.current_decay;
            }
            Some(CurrentLoop::Rl {
                resistance: r,
                inductance: l,
                back_emf: ke,
                kp,
                ki,
            }) => {
                let ns = ms.rl_substeps;
                let hs = ms.h / ns as f64;
                let v = s.v;
                let d =
                    |ia: f64, q: f64| ((kp * (ic - ia) + ki * q - r * ia - ke * v) / l, ic - ia);
                for _ in 0..ns {
                    let (a1, b1) = d(s.ia, s.q);
                    let (a2, b2) = d(s.ia + 0.5 * hs * a1, s.q + 0.5 * hs * b1);
                    let (a3, b3) = d(s.ia + 0.5 * hs * a2, s.q + 0.5 * hs * b2);
                    let (a4, b4) = d(s.ia + hs * a3, s.q + hs * b3);
                    s.ia += hs / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4);
                    s.q += hs / 6.0 * (b1 + 2.0 * b2 + 2.0 * b3 + b4);
                }
            }
        }
        let fm = self.kf * self.deadband(s.ia);
        match self.lag_w() {
            None => fm,
            Some(_) => {
                s.fl = fm + (s.fl - fm) * ms.lag_decay;
                s.fl
            }
        }
    }

    /// `at_state`: `(g, F)` at this state and time when already known (from a sample).
    #[inline(always)]
    fn step_exact(
        &self,
        s: &mut State,
        ic: f64,
        ms: &MotorStep,
        time: f64,
        at_state: Option<(f64, f64)>,
    ) {
        let h = ms.h;
        let fm = self.motor(s, ic, ms);
        if let Some(r) = self.res() {
            // two bodies: semi-implicit Euler for both, exact bristle update on the load
            let (g, f) = at_state.unwrap_or_else(|| {
                let (g, f, _) = self.friction(s.z, s.vl, self.scale(s.xl, time));
                (g, f)
            });
            let fc = r.k * (s.x - s.xl) + r.c * (s.v - s.vl);
            let am = (fm - fc) / r.mm;
            let al = (fc - f - self.effect_force(s.xl, s.vl)) / r.ml;
            s.z = self.fr.advance_z(s.z, s.vl, g, h);
            s.v += am * h;
            s.vl += al * h;
            s.x += s.v * h;
            s.xl += s.vl * h;
            return;
        }
        let (g, f) = at_state.unwrap_or_else(|| {
            let (g, f, _) = self.friction(s.z, s.v, self.scale(s.x, time));
            (g, f)
        });
        let a = (fm - f - self.effect_force(s.x, s.v)) / self.mass;
        s.z = self.fr.advance_z(s.z, s.v, g, h);
        s.v += a * h;
        s.x += s.v * h;
    }

    /// Pieces of an RK4 step of length `h` that keep `sigma0*|v|*h/g` of the friction
    /// at velocity `v` and position `x` under [`RK4_BRISTLE_LIMIT`].
    fn rk4_pieces(&self, z: f64, v: f64, x: f64, h: f64, time: f64) -> usize {
        if v == 0.0 {
            return 1;
        }
        let (g, _, _) = self.friction(z, v, self.scale(x, time));
        let q = self.fr.sigma0 * v.abs() * h / g;
        if q.is_nan() || q <= RK4_BRISTLE_LIMIT {
            // (NaN: the divergence check after the step reports it)
            1
        } else {
            (q / RK4_BRISTLE_LIMIT).ceil().min(RK4_MAX_PIECES) as usize
        }
    }

    /// RK4 on `(x, v, xl, vl, z)` of the two-mass axis, the motor force held.
    fn step_rk4_two_mass(&self, s: &mut State, fm: f64, r: &TwoMass, h: f64, time: f64) {
        let d = |x: f64, v: f64, xl: f64, vl: f64, z: f64, tm: f64| {
            let (_, f, zdot) = self.friction(z, vl, self.scale(xl, tm));
            let fc = r.k * (x - xl) + r.c * (v - vl);
            (
                v,
                (fm - fc) / r.mm,
                vl,
                (fc - f - self.effect_force(xl, vl)) / r.ml,
                zdot,
            )
        };
        let (x, v, xl, vl, z) = (s.x, s.v, s.xl, s.vl, s.z);
        let k1 = d(x, v, xl, vl, z, time);
        let k2 = d(
            x + 0.5 * h * k1.0,
            v + 0.5 * h * k1.1,
            xl + 0.5 * h * k1.2,
            vl + 0.5 * h * k1.3,
            z + 0.5 * h * k1.4,
            time + 0.5 * h,
        );
        let k3 = d(
            x + 0.5 * h * k2.0,
            v + 0.5 * h * k2.1,
            xl + 0.5 * h * k2.2,
            vl + 0.5 * h * k2.3,
            z + 0.5 * h * k2.4,
            time + 0.5 * h,
        );
        let k4 = d(
            x + h * k3.0,
            v + h * k3.1,
            xl + h * k3.2,
            vl + h * k3.3,
            z + h * k3.4,
            time + h,
        );
        s.x += h / 6.0 * (k1.0 + 2.0 * k2.0 + 2.0 * k3.0 + k4.0);
        s.v += h / 6.0 * (k1.1 + 2.0 * k2.1 + 2.0 * k3.1 + k4.1);
        s.xl += h / 6.0 * (k1.2 + 2.0 * k2.2 + 2.0 * k3.2 + k4.2);
        s.vl += h / 6.0 * (k1.3 + 2.0 * k2.3 + 2.0 * k3.3 + k4.3);
        s.z += h / 6.0 * (k1.4 + 2.0 * k2.4 + 2.0 * k3.4 + k4.4);
    }

    /// One plant step of RK4, the motor force held: in as many equal pieces as
    /// [`Physics::rk4_pieces`] asks for at the step's start (one while the bristles
    /// are slow against the step).
    fn step_rk4(&self, s: &mut State, ic: f64, ms: &MotorStep, time: f64) {
        let fm = self.motor(s, ic, ms);
        let (x, v) = match self.res() {
            Some(_) => (s.xl, s.vl),
            None => (s.x, s.v),
        };
        let p = self.rk4_pieces(s.z, v, x, ms.h, time);
        let h = ms.h / p as f64;
        for j in 0..p {
            let tj = time + j as f64 * h;
            match self.res() {
                Some(r) => self.step_rk4_two_mass(s, fm, r, h, tj),
                None => self.step_rk4_one_mass(s, fm, h, tj),
            }
        }
    }

    /// RK4 on `(x, v, z)` of the rigid axis, the motor force held.
    fn step_rk4_one_mass(&self, s: &mut State, fm: f64, h: f64, time: f64) {
        let d = |x: f64, v: f64, z: f64, tm: f64| {
            let (a, _, zdot) = self.accel(fm, x, v, z, tm);
            (v, a, zdot)
        };
        let (x, v, z) = (s.x, s.v, s.z);
        let k1 = d(x, v, z, time);
        let k2 = d(
            x + 0.5 * h * k1.0,
            v + 0.5 * h * k1.1,
            z + 0.5 * h * k1.2,
            time + 0.5 * h,
        );
        let k3 = d(
            x + 0.5 * h * k2.0,
            v + 0.5 * h * k2.1,
            z + 0.5 * h * k2.2,
            time + 0.5 * h,
        );
        let k4 = d(x + h * k3.0, v + h * k3.1, z + h * k3.2, time + h);
        s.x += h / 6.0 * (k1.0 + 2.0 * k2.0 + 2.0 * k3.0 + k4.0);
        s.v += h / 6.0 * (k1.1 + 2.0 * k2.1 + 2.0 * k3.1 + k4.1);
        s.z += h / 6.0 * (k1.2 + 2.0 * k2.2 + 2.0 * k3.2 + k4.2);
    }
}

/// Validate the inputs of [`simulate`].
pub fn check_inputs(model: &Model, t: &[f64], drive: &Drive, opts: &SimOptions) -> Result<()> {
    check_time("t", t)?;
    let (name, a) = match drive {
        Drive::Position(a) => ("x_ref", a),
        Drive::Speed(a) => ("v_ref", a),
        Drive::Current(a) => ("i", a),
    };
    check_len(name, a, t.len(), "t")?;
    check_finite(name, a)?;
    if opts.substeps == 0 {
        return Err(Error::parameter("substeps", 0.0, "must be at least 1"));
    }
    for (nm, val) in [
        ("z0", opts.z0),
        ("v0", opts.v0),
        ("x0", opts.x0.unwrap_or(0.0)),
    ] {
        if !val.is_finite() {
            return Err(Error::parameter(nm, val, "must be finite"));
        }
    }
    match drive {
        Drive::Current(_) => {
            if t.len() < 2 {
                return Err(Error::input(
                    "t",
                    "open-loop simulation needs at least two samples",
                ));
            }
        }
        Drive::Position(_) | Drive::Speed(_) => {
            let c = model.controller.as_ref().ok_or_else(|| {
                Error::model(
                    "controller",
                    "is missing: closed-loop simulation needs a controller (add one, or drive the axis with a current)",
                )
            })?;
            match (c.law, drive) {
                (ControlLaw::Pid { .. }, Drive::Speed(_)) => {
                    return Err(Error::input(
                        "v_ref",
                        "the model's controller is a position PID: give x_ref instead",
                    ))
                }
                (ControlLaw::PiSpeed { .. }, Drive::Position(_)) => {
                    return Err(Error::input(
                        "x_ref",
                        "the model's controller is a PI speed loop: give v_ref instead",
                    ))
                }
                _ => {}
            }
        }
    }
    Ok(())
}

/// The longest plant step [s] of a run: one control period (or, in open loop, one mean
/// sample interval) over `substeps`.
fn max_step(model: &Model, t: &[f64], drive: &Drive, substeps: usize) -> f64 {
    let n = t.len();
    match (drive, &model.controller) {
        (Drive::Position(_) | Drive::Speed(_), Some(c)) => 1.0 / (c.rate_hz * substeps as f64),
        _ => (t[n - 1] - t[0]) / (n - 1) as f64 / substeps as f64,
    }
}

/// Refuse a `resonance` too stiff for the plant step.
///
/// Semi-implicit Euler on the relative motion of motor and load (angular frequency `w`,
/// damping ratio `zeta` of the free mode) is stable for
/// `w*h < 2*(sqrt(1 + zeta^2) - zeta)`; the simulation asks for half of that, which
/// keeps the mode's frequency and damping within a few per cent (`docs/DESIGN.md`).
pub fn check_resonance_step(
    model: &Model,
    t: &[f64],
    drive: &Drive,
    opts: &SimOptions,
) -> Result<()> {
    for e in &model.effects {
        if let Effect::Resonance {
            frequency_hz,
            damping_ratio,
            load_fraction,
        } = e
        {
            let tm = TwoMass::new(
                model.total_mass(),
                *frequency_hz,
                *damping_ratio,
                *load_fraction,
            );
            let (w, zeta) = tm.free_mode();
            let limit = (1.0 + zeta * zeta).sqrt() - zeta;
            let h = max_step(model, t, drive, opts.substeps);
            if w * h > limit {
                let need = (opts.substeps as f64 * w * h / limit).ceil();
                return Err(Error::parameter(
                    "substeps",
                    opts.substeps as f64,
                    format!(
                        "is too few for the resonance effect: its free motor-load mode at \
                         {:.1} Hz needs plant steps below {:.3} of its period; use \
                         substeps >= {need} (or a higher control rate)",
                        w / (2.0 * PI),
                        limit / (2.0 * PI),
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// Simulate the axis sampled at `t`.
///
/// `keep_going` is called once the first few thousand plant steps are done, then about
/// every [`POLL_INTERVAL`] of run time; returning `false` stops the run with
/// [`Error::Interrupted`].
///
/// ```
/// use lugre::servo::{simulate, Drive, Model, SimOptions};
/// let m = Model::from_json(r#"{"axis": {"mass": 25, "force_constant": 25},
///   "friction": {"sigma0": 1e5, "sigma1": 31.62,
///     "positive": {"fc": 28.7, "fs": 60.2, "sigma2": 332.5, "vs": 0.01},
///     "negative": {"fc": 28.5, "fs": 60.1, "sigma2": 333.0, "vs": 0.01}},
///   "controller": {"type": "pid", "kp": 5e4, "ki": 5e5, "kd": 1500, "rate_hz": 10000}}"#).unwrap();
/// let t: Vec<f64> = (0..10001).map(|k| k as f64 * 1e-4).collect();
/// let xr: Vec<f64> = t.iter().map(|&s| 0.01 * s).collect();
/// let r = simulate(&m, &t, Drive::Position(&xr), &SimOptions::default(), &mut || true).unwrap();
/// assert!((r.x[10000] - 0.01).abs() < 2e-3);
/// ```
pub fn simulate(
    model: &Model,
    t: &[f64],
    drive: Drive,
    opts: &SimOptions,
    keep_going: &mut dyn FnMut() -> bool,
) -> Result<SimResult> {
    check_inputs(model, t, &drive, opts)?;
    check_resonance_step(model, t, &drive, opts)?;
    // one instance of the event loop per kind of physics and integrator
    let plain = is_plain(model);
    let t0 = t[0];
    match (plain, opts.integrator) {
        (true, Integrator::Exact) => {
            run::<false, false>(model, t, drive, opts, keep_going, &Physics::new(model, t0))
        }
        (true, Integrator::Rk4) => {
            run::<false, true>(model, t, drive, opts, keep_going, &Physics::new(model, t0))
        }
        (false, Integrator::Exact) => {
            run::<true, false>(model, t, drive, opts, keep_going, &Physics::new(model, t0))
        }
        (false, Integrator::Rk4) => {
            run::<true, true>(model, t, drive, opts, keep_going, &Physics::new(model, t0))
        }
    }
}

/// The event loop of [`simulate`] (`docs/DESIGN.md`) on checked inputs, for the
/// physics `EXTRAS` (see [`Physics`]) and the RK4 (`RK4`) or exact integrator.
fn run<const EXTRAS: bool, const RK4: bool>(
    model: &Model,
    t: &[f64],
    drive: Drive,
    opts: &SimOptions,
    keep_going: &mut dyn FnMut() -> bool,
    phys: &Physics<EXTRAS>,
) -> Result<SimResult> {
    let n_out = t.len();
    let t0 = t[0];
    let open_loop = matches!(drive, Drive::Current(_));
    let (rate, ctrl) = match (&model.controller, open_loop) {
        (Some(c), false) => (c.rate_hz, Some(c)),
        _ => (0.0, None),
    };
    let h_max = if open_loop {
        (t[n_out - 1] - t0) / (n_out - 1) as f64 / opts.substeps as f64
    } else {
        1.0 / (rate * opts.substeps as f64)
    };
    let tol = if open_loop {
        1e-9 * (t[n_out - 1] - t0) / (n_out - 1) as f64
    } else {
        1e-9 / rate
    };
    let reference = match drive {
        Drive::Position(a) | Drive::Speed(a) | Drive::Current(a) => a,
    };
    let mut interp = Interp {
        t,
        y: reference,
        j: 0,
    };
    let x_init = opts.x0.unwrap_or(match drive {
        Drive::Position(a) => a[0],
        _ => 0.0,
    });
    let mut s = State {
        x: x_init,
        v: opts.v0,
        z: opts.z0,
        ia: 0.0,
        q: 0.0,
        fl: 0.0,
        xl: x_init,
        vl: opts.v0,
    };
    let mut ff = ctrl
        .and_then(|c| c.feedforward.as_ref())
        .map(|f| (f.kind, f.friction, Compensator::new(f.friction)));
    let mut out = SimResult {
        x: Vec::with_capacity(n_out),
        v: Vec::with_capacity(n_out),
        z: Vec::with_capacity(n_out),
        i: Vec::with_capacity(n_out),
        friction: Vec::with_capacity(n_out),
        force: Vec::with_capacity(n_out),
    };
    let mut queue: VecDeque<(f64, f64)> = VecDeque::new();
    let mut xi = 0.0;
    let mut xr_prev = 0.0;
    let mut ic = 0.0; // latest command
    let mut ic_eff = 0.0; // command acting on the drive (after delay)
    let mut time = t0;
    let mut k = 0usize;
    let mut n = 0usize;
    let ctrl_time = |n: usize| -> f64 {
        if open_loop {
            if n < n_out {
                t[n]
            } else {
                f64::INFINITY
            }
        } else {
            // n < 2^53: the signed conversion is exact and one instruction
            t0 + n as i64 as f64 / rate
        }
    };
    let mut tc = ctrl_time(0);
    let mut since_check = 0usize;
    // `None` until the first poll, so a run that is stopped before it starts ends within
    // its first POLL_STEPS steps whatever the speed of the machine.
    let mut last_poll: Option<Instant> = None;
    loop {
        if time >= tc - tol {
            // controller (or open-loop command) update
            if let Some(c) = ctrl {
                let xr = interp.at(tc);
                let (u, vr) = match c.law {
                    ControlLaw::Pid { kp, ki, kd } => {
                        let xr_dot = if n == 0 { 0.0 } else { (xr - xr_prev) * rate };
                        xr_prev = xr;
                        let e = xr - s.x;
                        xi += e / rate;
                        (kp * e + ki * xi + kd * (xr_dot - s.v), xr_dot)
                    }
                    ControlLaw::PiSpeed { kp, ki } => {
                        let e = xr - s.v;
                        xi += e / rate;
                        (kp * e + ki * xi, xr)
                    }
                };
                let f_ff = match &mut ff {
                    None => 0.0,
                    Some((FeedforwardKind::Static, p, _)) => p.stribeck(vr),
                    Some((FeedforwardKind::Lugre, _, comp)) => comp.step(vr, 1.0 / rate),
                };
                ic = (u + f_ff) / phys.kf;
                if let Some(lim) = model.axis.current_limit {
                    ic = ic.clamp(-lim, lim);
                }
            } else {
                ic = reference[n];
            }
            match phys.delay() {
                None => ic_eff = ic,
                Some(d) => queue.push_back((tc + d, ic)),
            }
            n += 1;
            tc = ctrl_time(n);
        }
        let mut at_state = None;
        if k < n_out && t[k] <= time + tol {
            // Record the samples due now. The friction is evaluated here, under this
            // test: inside the loop below, the compiler would hoist the evaluation (an
            // exp()) out of it and run it at every event, sample or not.
            let (xl, vl) = phys.load(&s);
            let sc = phys.scale(xl, time);
            let (g, f, _) = phys.friction(s.z, vl, sc);
            // the next plant step starts from this state: it reuses (g, F)
            at_state = Some((g, f));
            let fm = phys.kf
                * phys.deadband(if phys.current_loop().is_some() {
                    s.ia
                } else if phys.delay().is_some() {
                    ic_eff_peek(&queue, ic_eff, time, tol)
                } else {
                    ic_eff
                });
            let i = if phys.current_loop().is_some() {
                s.ia
            } else {
                ic
            };
            let force = match phys.lag_w() {
                Some(_) => s.fl,
                None => fm,
            };
            while k < n_out && t[k] <= time + tol {
                out.x.push(s.x);
                out.v.push(s.v);
                out.z.push(s.z);
                out.i.push(i);
                out.friction.push(f);
                out.force.push(force);
                k += 1;
            }
        }
        if k == n_out {
            break;
        }
        // min(tc, t[k]) of two finite times (f64::min would also handle NaN)
        let next = if t[k] < tc { t[k] } else { tc };
        // max(1, ceil(span/h_max - 1e-6)) plant steps; one in the usual case, without
        // the call to ceil() (a libm call on baseline x86-64)
        let r = (next - time) / h_max - 1e-6;
        let m = if r <= 1.0 {
            1
        } else {
            (r.ceil() as usize).max(1)
        };
        let h = if m == 1 {
            next - time
        } else {
            (next - time) / m as f64
        };
        let ms = phys.motor_step(h);
        for j in 0..m {
            let tj = time + j as f64 * h;
            if phys.delay().is_some() {
                while let Some(&(te, val)) = queue.front() {
                    if te <= tj + tol {
                        ic_eff = val;
                        queue.pop_front();
                    } else {
                        break;
                    }
                }
            }
            if RK4 {
                phys.step_rk4(&mut s, ic_eff, &ms, tj);
            } else {
                phys.step_exact(&mut s, ic_eff, &ms, tj, at_state.take());
            }
        }
        if !(s.x.is_finite()
            && s.v.is_finite()
            && s.z.is_finite()
            && (!EXTRAS || (s.xl.is_finite() && s.vl.is_finite())))
        {
            let hint = if open_loop {
                "check the current against the mass, or give more substeps"
            } else {
                "check the controller gains against the mass and the control rate, or give \
                 more substeps"
            };
            return Err(Error::Data(format!(
                "the simulation diverged at t = {time}: {hint}"
            )));
        }
        time = next;
        since_check += m;
        if since_check >= POLL_STEPS {
            since_check = 0;
            if last_poll.is_none_or(|p| p.elapsed() >= POLL_INTERVAL) {
                if !keep_going() {
                    return Err(Error::Interrupted);
                }
                last_poll = Some(Instant::now());
            }
        }
    }
    Ok(out)
}

/// The delayed command that would act at `time` (for reporting the motor force).
fn ic_eff_peek(queue: &VecDeque<(f64, f64)>, current: f64, time: f64, tol: f64) -> f64 {
    let mut v = current;
    for &(te, val) in queue {
        if te <= time + tol {
            v = val;
        } else {
            break;
        }
    }
    v
}

/// Simulate many models on the same input in parallel (rayon).
pub fn simulate_batch(
    models: &[Model],
    t: &[f64],
    drive: Drive,
    opts: &SimOptions,
) -> Vec<Result<SimResult>> {
    simulate_batch_with(models, t, drive, opts, &AtomicBool::new(false))
}

/// As [`simulate_batch`], stopping every run with [`Error::Interrupted`] once `cancel`
/// is set (from another thread, e.g. on Ctrl-C).
pub fn simulate_batch_with(
    models: &[Model],
    t: &[f64],
    drive: Drive,
    opts: &SimOptions,
    cancel: &AtomicBool,
) -> Vec<Result<SimResult>> {
    use rayon::prelude::*;
    models
        .par_iter()
        .map(|m| simulate(m, t, drive, opts, &mut || !cancel.load(Ordering::Relaxed)))
        .collect()
}
