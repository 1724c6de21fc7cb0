//! The plant of the simulation: the axis with its friction and extra physics, flattened
//! for the inner loop ([`Physics`]), its state, and one plant step by the exact
//! bristle update or by RK4.

use super::RK4_BRISTLE_LIMIT;
use crate::friction::LugreParams;
use crate::servo::effects::{eval_loaded, Actuator, EffectForces, FrictionScale};
use crate::servo::model::{CurrentLoop, Effect, Model};
use std::f64::consts::PI;

/// Most pieces of one RK4 plant step (a guard against absurd parameters).
const RK4_MAX_PIECES: f64 = 1e4;

/// Extra physics, flattened for the inner loop.
///
/// `EXTRAS = false` is the plain axis (no current loop, current lag, delay, cogging,
/// scaled friction, resonance, dead band, drag, Stribeck shape, gravity, load friction,
/// force ripple or current limit; springs and offsets are kept): the simulation loop is
/// compiled once
/// for it, with every test of the absent physics removed, and once for the general case.
/// Both run the same code, so their results are identical.
pub(super) struct Physics<const EXTRAS: bool> {
    mass: f64,
    pub(super) kf: f64,
    fr: LugreParams<f64>,
    /// Cogging, springs, offsets, drag and gravity.
    forces: EffectForces,
    /// `position_friction` and `drift`.
    scales: FrictionScale,
    current_loop: Option<CurrentLoop>,
    lag_w: Option<f64>,
    delay: Option<f64>,
    t0: f64,
    /// `stribeck_shape` exponent.
    shape: Option<f64>,
    /// `deadband`, `current_limit`, `force_ripple` and `load_friction`.
    act: Actuator,
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
    pub(super) fn free_mode(&self) -> (f64, f64) {
        let mu = self.mm * self.ml / (self.mm + self.ml);
        let w = (self.k / mu).sqrt();
        (w, self.c / (2.0 * mu * w))
    }
}

/// True when the model needs none of the extras of [`Physics`].
pub(super) fn is_plain(m: &Model) -> bool {
    m.axis.current_loop.is_none()
        && m.effects.iter().all(|e| {
            matches!(
                e,
                Effect::Spring { .. } | Effect::Offset { .. } | Effect::Mass { .. }
            )
        })
}

impl<const EXTRAS: bool> Physics<EXTRAS> {
    pub(super) fn new(m: &Model, t0: f64) -> Self {
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
            act: Actuator::new(&m.effects),
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
                Effect::StribeckShape { exponent } => p.shape = Some(*exponent),
                // forces and friction scales: `forces`, `scales`; the actuator: `act`;
                // mass: `total_mass`
                Effect::Deadband { .. }
                | Effect::CurrentLimit { .. }
                | Effect::ForceRipple { .. }
                | Effect::LoadFriction { .. }
                | Effect::Gravity { .. }
                | Effect::Cogging { .. }
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
    pub(super) fn current_loop(&self) -> Option<&CurrentLoop> {
        if EXTRAS {
            self.current_loop.as_ref()
        } else {
            None
        }
    }

    #[inline(always)]
    pub(super) fn lag_w(&self) -> Option<f64> {
        if EXTRAS {
            self.lag_w
        } else {
            None
        }
    }

    #[inline(always)]
    pub(super) fn delay(&self) -> Option<f64> {
        if EXTRAS {
            self.delay
        } else {
            None
        }
    }

    #[inline(always)]
    pub(super) fn scale(&self, x: f64, time: f64) -> f64 {
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
    pub(super) fn load(&self, s: &State) -> (f64, f64) {
        if self.res().is_some() {
            (s.xl, s.vl)
        } else {
            (s.x, s.v)
        }
    }

    /// `(g, F, zdot)` of the plant's friction (generalised Stribeck curve with a
    /// `stribeck_shape`, levels raised by a `load_friction` under the motor force `fm`).
    #[inline(always)]
    pub(super) fn friction(&self, z: f64, v: f64, scale: f64, fm: f64) -> (f64, f64, f64) {
        if EXTRAS {
            if self.act.load.is_some() {
                return eval_loaded(&self.fr, z, v, scale, self.act.level(fm), self.shape);
            }
            if let Some(e) = self.shape {
                return self.fr.eval_shaped(z, v, scale, e);
            }
        }
        self.fr.eval(z, v, scale)
    }

    /// Whether the friction depends on the motor force (a `load_friction`).
    #[inline(always)]
    pub(super) fn loaded(&self) -> bool {
        EXTRAS && self.act.load.is_some()
    }

    /// The motor force before a `current_lag` of the current `i` the drive is given:
    /// `K_F*clip(db(i))` (`deadband`, then `current_limit`).
    #[inline(always)]
    pub(super) fn drive_force(&self, i: f64) -> f64 {
        if EXTRAS {
            self.kf * self.act.current(i)
        } else {
            self.kf * i
        }
    }

    /// The motor force acting on the motor at position `x`: `f` (after any lag) times a
    /// `force_ripple`'s factor.
    #[inline(always)]
    pub(super) fn ripple(&self, f: f64, x: f64) -> f64 {
        if EXTRAS {
            self.act.ripple(f, x)
        } else {
            f
        }
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
        let (g, f, zdot) = self.friction(z, v, s, fm);
        ((fm - f - self.effect_force(x, v)) / self.mass, g, zdot)
    }
}

#[derive(Debug, Clone, Copy)]
pub(super) struct State {
    /// Position [m] (of the motor with a `resonance`).
    pub(super) x: f64,
    /// Velocity [m/s].
    pub(super) v: f64,
    /// Bristle deflection [m].
    pub(super) z: f64,
    /// Actual current of a current loop [A].
    pub(super) ia: f64,
    /// Integral of the current error of an R-L current loop's PI [A s].
    pub(super) q: f64,
    /// Motor force after the `current_lag` [N].
    pub(super) fl: f64,
    /// Load position and velocity (`resonance`; unused without it).
    pub(super) xl: f64,
    pub(super) vl: f64,
}

/// The factors of the motor update that depend only on the step length `h`, computed
/// once per interval between events rather than once per plant step (and only for the
/// physics the model has: the compiler would otherwise hoist every `exp()` of
/// [`Physics::motor`] out of the step loop and run them all at each event).
#[derive(Debug, Clone, Copy)]
pub(super) struct MotorStep {
    h: f64,
    /// `exp(-2*pi*f*h)` of a first-order current loop.
    current_decay: f64,
    /// RK4 sub-steps of an R-L current loop.
    rl_substeps: usize,
    /// `exp(-2*pi*bw*h)` of the `current_lag` effect.
    lag_decay: f64,
}

impl<const EXTRAS: bool> Physics<EXTRAS> {
    pub(super) fn motor_step(&self, h: f64) -> MotorStep {
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

    /// Advance the current (loop) and the lagged force over h; returns the motor force
    /// (after the actuator: dead band, current limit, lag, ripple at the step's start).
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
        let fm = self.drive_force(s.ia);
        let f = match self.lag_w() {
            None => fm,
            Some(_) => {
                s.fl = fm + (s.fl - fm) * ms.lag_decay;
                s.fl
            }
        };
        self.ripple(f, s.x)
    }

    /// `at_state`: `(g, F)` at this state and time when already known (from a sample;
    /// not used with a `load_friction`, whose friction follows this step's motor force).
    #[inline(always)]
    pub(super) fn step_exact(
        &self,
        s: &mut State,
        ic: f64,
        ms: &MotorStep,
        time: f64,
        at_state: Option<(f64, f64)>,
    ) {
        let h = ms.h;
        let fm = self.motor(s, ic, ms);
        let at_state = if self.loaded() { None } else { at_state };
        if let Some(r) = self.res() {
            // two bodies: semi-implicit Euler for both, exact bristle update on the load
            let (g, f) = at_state.unwrap_or_else(|| {
                let (g, f, _) = self.friction(s.z, s.vl, self.scale(s.xl, time), fm);
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
            let (g, f, _) = self.friction(s.z, s.v, self.scale(s.x, time), fm);
            (g, f)
        });
        let a = (fm - f - self.effect_force(s.x, s.v)) / self.mass;
        s.z = self.fr.advance_z(s.z, s.v, g, h);
        s.v += a * h;
        s.x += s.v * h;
    }

    /// Pieces of an RK4 step of length `h` that keep `sigma0*|v|*h/g` of the friction
    /// at velocity `v` and position `x` (motor force `fm`) under [`RK4_BRISTLE_LIMIT`].
    fn rk4_pieces(&self, z: f64, v: f64, x: f64, fm: f64, h: f64, time: f64) -> usize {
        if v == 0.0 {
            return 1;
        }
        let (g, _, _) = self.friction(z, v, self.scale(x, time), fm);
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
            let (_, f, zdot) = self.friction(z, vl, self.scale(xl, tm), fm);
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
    pub(super) fn step_rk4(&self, s: &mut State, ic: f64, ms: &MotorStep, time: f64) {
        let fm = self.motor(s, ic, ms);
        let (x, v) = match self.res() {
            Some(_) => (s.xl, s.vl),
            None => (s.x, s.v),
        };
        let p = self.rk4_pieces(s.z, v, x, fm, ms.h, time);
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
