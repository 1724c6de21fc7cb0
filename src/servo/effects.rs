//! The effects of the model vocabulary: their names and parser, and what they do to the
//! moving body, defined once for the simulator ([`super::sim`]) and the inverse dynamics
//! ([`crate::inverse`]): the force of a `cogging`, `spring`, `offset`, `drag` or
//! `gravity` at `(x, v)`, the factor of a `position_friction` or `drift` on the friction
//! levels, and the actuator between the current and the motor force (`deadband`,
//! `current_limit`, `force_ripple`) with the friction its force adds (`load_friction`),
//! `Actuator`.
//!
//! The simulator adds the forces up in its own order, gathered once per run
//! (`EffectForces`: the springs and offsets as one `a*x + b`, the drags as one
//! coefficient), the inverse dynamics effect by effect ([`Effect::add_force`]); the
//! two sums agree to rounding, and each is the order its NumPy twin repeats to the last
//! bit (`lugre.reference`). Likewise the inverse dynamics interpolates a
//! `position_friction` over the whole record as `numpy.interp` does.

use super::model::{get, join, nonneg, num, num_list, opt_num, positive, Effect};
use crate::error::{Error, Result};
use crate::friction::{LugreParams, StaticSet};
use core::f64::consts::PI;
use serde_json::Value;

// The effect names of the model file, spelled here only.
const COGGING: &str = "cogging";
const SPRING: &str = "spring";
const OFFSET: &str = "offset";
const POSITION_FRICTION: &str = "position_friction";
const DRIFT: &str = "drift";
const MASS: &str = "mass";
/// The name a rotary axis may give its `mass` effect (read as `mass`).
const INERTIA: &str = "inertia";
const DELAY: &str = "delay";
const CURRENT_LAG: &str = "current_lag";
const RESONANCE: &str = "resonance";
const DEADBAND: &str = "deadband";
const DRAG: &str = "drag";
const STRIBECK_SHAPE: &str = "stribeck_shape";
const GRAVITY: &str = "gravity";
const LOAD_FRICTION: &str = "load_friction";
const FORCE_RIPPLE: &str = "force_ripple";
const CURRENT_LIMIT: &str = "current_limit";

/// Every effect name of the model file (`"effect": name`), in the order [`Effect`]
/// declares its variants (the CONTRACT's).
pub const EFFECT_NAMES: [&str; 16] = [
    COGGING,
    SPRING,
    OFFSET,
    POSITION_FRICTION,
    DRIFT,
    MASS,
    DELAY,
    CURRENT_LAG,
    RESONANCE,
    DEADBAND,
    DRAG,
    STRIBECK_SHAPE,
    GRAVITY,
    LOAD_FRICTION,
    FORCE_RIPPLE,
    CURRENT_LIMIT,
];

impl Effect {
    /// The effect's name in the model file (one of [`EFFECT_NAMES`]).
    pub fn name(&self) -> &'static str {
        match self {
            Effect::Cogging { .. } => COGGING,
            Effect::Spring { .. } => SPRING,
            Effect::Offset { .. } => OFFSET,
            Effect::PositionFriction { .. } => POSITION_FRICTION,
            Effect::Drift { .. } => DRIFT,
            Effect::Mass { .. } => MASS,
            Effect::Delay { .. } => DELAY,
            Effect::CurrentLag { .. } => CURRENT_LAG,
            Effect::Resonance { .. } => RESONANCE,
            Effect::Deadband { .. } => DEADBAND,
            Effect::Drag { .. } => DRAG,
            Effect::StribeckShape { .. } => STRIBECK_SHAPE,
            Effect::Gravity { .. } => GRAVITY,
            Effect::LoadFriction { .. } => LOAD_FRICTION,
            Effect::ForceRipple { .. } => FORCE_RIPPLE,
            Effect::CurrentLimit { .. } => CURRENT_LIMIT,
        }
    }
}

/// Parse one entry of the model's `effects` list (`path`: its place, for errors).
pub(super) fn parse_effect(e: &Value, path: &str) -> Result<Effect> {
    let kind = get(e, "effect", path)?
        .as_str()
        .ok_or_else(|| Error::model(&join(path, "effect"), "must be a string"))?;
    let n = |k: &str| num(e, k, path);
    let p = |k: &str| join(path, k);
    let phase = || Ok::<f64, Error>(opt_num(e, "phase", path)?.unwrap_or(0.0));
    Ok(match kind {
        // (the harmonics are read first: the twin checks in this order)
        COGGING => Effect::Cogging {
            harmonics: parse_harmonics(e, path)?,
            amplitude: n("amplitude")?,
            pitch: positive(n("pitch")?, &p("pitch"))?,
            phase: phase()?,
        },
        SPRING => Effect::Spring {
            stiffness: n("stiffness")?,
            x0: opt_num(e, "x0", path)?.unwrap_or(0.0),
        },
        OFFSET => Effect::Offset { force: n("force")? },
        POSITION_FRICTION => parse_position_friction(e, path)?,
        DRIFT => Effect::Drift {
            gain: below_one(n("gain")?, &p("gain"))?,
            time_constant: positive(n("time_constant")?, &p("time_constant"))?,
        },
        MASS | INERTIA => Effect::Mass { delta: n("delta")? },
        DELAY => Effect::Delay {
            seconds: nonneg(n("seconds")?, &p("seconds"))?,
        },
        CURRENT_LAG => Effect::CurrentLag {
            bandwidth_hz: positive(n("bandwidth")?, &p("bandwidth"))?,
        },
        RESONANCE => Effect::Resonance {
            frequency_hz: positive(n("frequency")?, &p("frequency"))?,
            damping_ratio: nonneg(n("damping_ratio")?, &p("damping_ratio"))?,
            load_fraction: fraction(n("load_fraction")?, &p("load_fraction"))?,
        },
        DEADBAND => Effect::Deadband {
            current: nonneg(n("current")?, &p("current"))?,
        },
        DRAG => Effect::Drag {
            coefficient: nonneg(n("coefficient")?, &p("coefficient"))?,
        },
        STRIBECK_SHAPE => Effect::StribeckShape {
            exponent: positive(n("exponent")?, &p("exponent"))?,
        },
        GRAVITY => Effect::Gravity {
            torque: n("torque")?,
            phase: phase()?,
        },
        LOAD_FRICTION => Effect::LoadFriction {
            coefficient: nonneg(n("coefficient")?, &p("coefficient"))?,
        },
        FORCE_RIPPLE => Effect::ForceRipple {
            amplitude: ripple_amplitude(n("amplitude")?, &p("amplitude"))?,
            pitch: positive(n("pitch")?, &p("pitch"))?,
            phase: phase()?,
        },
        CURRENT_LIMIT => Effect::CurrentLimit {
            current: positive(n("current")?, &p("current"))?,
        },
        other => {
            return Err(Error::model(
                &join(path, "effect"),
                format!(
                    "unknown effect \"{other}\": use one of {}",
                    EFFECT_NAMES.join(", ")
                ),
            ))
        }
    })
}

/// A `cogging`'s optional `harmonics`: `[amplitude, phase]` of harmonics 2, 3, ...
fn parse_harmonics(e: &Value, path: &str) -> Result<Vec<(f64, f64)>> {
    let h = match e.get("harmonics") {
        None | Some(Value::Null) => return Ok(Vec::new()),
        Some(h) => h,
    };
    let hp = join(path, "harmonics");
    let a = h
        .as_array()
        .ok_or_else(|| Error::model(&hp, "must be a list of [amplitude, phase] pairs"))?;
    a.iter()
        .enumerate()
        .map(|(k, pair)| {
            let q = num_list(pair, &format!("{hp}[{k}]"))?;
            if q.len() != 2 {
                return Err(Error::model(
                    &format!("{hp}[{k}]"),
                    "must be [amplitude, phase]",
                ));
            }
            Ok((q[0], q[1]))
        })
        .collect()
}

/// A `position_friction`: breakpoints strictly increasing, one positive scale each.
fn parse_position_friction(e: &Value, path: &str) -> Result<Effect> {
    let p = |k: &str| join(path, k);
    let positions = num_list(get(e, "positions", path)?, &p("positions"))?;
    let scale = num_list(get(e, "scale", path)?, &p("scale"))?;
    if positions.is_empty() || positions.len() != scale.len() {
        return Err(Error::model(
            &p("scale"),
            format!(
                "has {} values for {} positions: give one scale per position",
                scale.len(),
                positions.len()
            ),
        ));
    }
    if let Some(k) = positions.windows(2).position(|w| w[1] <= w[0]) {
        return Err(Error::model(
            &format!("{}[{}]", p("positions"), k + 1),
            "positions must be strictly increasing",
        ));
    }
    for (k, &s) in scale.iter().enumerate() {
        positive(s, &format!("{}[{k}]", p("scale")))?;
    }
    Ok(Effect::PositionFriction { positions, scale })
}

/// A `drift`'s gain, below 1.
fn below_one(gain: f64, path: &str) -> Result<f64> {
    if gain >= 1.0 {
        return Err(Error::parameter(
            path,
            gain,
            "must be below 1 (friction would vanish or turn negative)",
        ));
    }
    Ok(gain)
}

/// A `resonance`'s load fraction, strictly between 0 and 1.
fn fraction(r: f64, path: &str) -> Result<f64> {
    if !(r > 0.0 && r < 1.0) {
        return Err(Error::parameter(
            path,
            r,
            "must lie strictly between 0 and 1 (the load's share of the total mass)",
        ));
    }
    Ok(r)
}

/// A `force_ripple`'s amplitude, strictly between -1 and 1.
fn ripple_amplitude(a: f64, path: &str) -> Result<f64> {
    if a.abs() >= 1.0 {
        return Err(Error::parameter(
            path,
            a,
            "must lie strictly between -1 and 1 (a share of the force constant: at 1 the \
             motor force would vanish at some positions)",
        ));
    }
    Ok(a)
}

/// One term `amplitude*sin(wavenumber*x + phase)` of a `cogging` force.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sine {
    /// Amplitude [N].
    pub amplitude: f64,
    /// Wavenumber `2*pi*k/pitch` of harmonic `k` [rad/m].
    pub wavenumber: f64,
    /// Phase [rad].
    pub phase: f64,
}

impl Sine {
    /// The force of the term at position `x` [m].
    #[inline(always)]
    pub fn at(&self, x: f64) -> f64 {
        self.amplitude * (self.wavenumber * x + self.phase).sin()
    }
}

impl Effect {
    /// The terms of a `cogging` force, the base harmonic first, then harmonics 2, 3, ...;
    /// the one term of a `gravity` (`torque*sin(1*x + phase)`, `x` in rad); none for the
    /// other effects.
    pub fn sines(&self) -> impl Iterator<Item = Sine> + '_ {
        let (base, harmonics) = match self {
            Effect::Gravity { torque, phase } => (
                Some(Sine {
                    amplitude: *torque,
                    wavenumber: 1.0,
                    phase: *phase,
                }),
                &[][..],
            ),
            Effect::Cogging {
                amplitude,
                pitch,
                phase,
                harmonics,
            } => (
                Some(Sine {
                    amplitude: *amplitude,
                    wavenumber: 2.0 * PI / pitch,
                    phase: *phase,
                }),
                harmonics.as_slice(),
            ),
            _ => (None, &[][..]),
        };
        let w = base.map_or(0.0, |s| s.wavenumber);
        base.into_iter()
            .chain(harmonics.iter().enumerate().map(move |(k, &(a, ph))| Sine {
                amplitude: a,
                wavenumber: w * (k as f64 + 2.0),
                phase: ph,
            }))
    }

    /// Whether the effect is a force on the moving body (`cogging`, `spring`, `offset`,
    /// `drag`, `gravity`).
    pub fn is_force(&self) -> bool {
        matches!(
            self,
            Effect::Cogging { .. }
                | Effect::Spring { .. }
                | Effect::Offset { .. }
                | Effect::Drag { .. }
                | Effect::Gravity { .. }
        )
    }

    /// `acc` plus the force [N] of the effect on the moving body at position `x` [m] and
    /// velocity `v` [m/s], its terms added one by one (a cogging's harmonics in turn);
    /// `acc` itself for an effect that is no force ([`Effect::is_force`]).
    ///
    /// `cogging`: `sum_k A_k*sin(k*2*pi*x/pitch + phase_k)`; `spring`: `k*(x - x0)`;
    /// `offset`: the constant force; `drag`: `coefficient*|v|*v`; `gravity`:
    /// `torque*sin(x + phase)`.
    #[inline]
    pub fn add_force(&self, acc: f64, x: f64, v: f64) -> f64 {
        match self {
            Effect::Cogging { .. } | Effect::Gravity { .. } => {
                self.sines().fold(acc, |f, s| f + s.at(x))
            }
            Effect::Spring { stiffness, x0 } => acc + stiffness * (x - x0),
            Effect::Offset { force } => acc + force,
            Effect::Drag { coefficient } => acc + coefficient * v.abs() * v,
            _ => acc,
        }
    }

    /// The force [N] of the effect at `(x, v)`: [`Effect::add_force`] onto zero.
    pub fn force(&self, x: f64, v: f64) -> f64 {
        self.add_force(0.0, x, v)
    }

    /// The factor of a `position_friction` (at position `x` [m], clamped linear
    /// interpolation between its breakpoints) or a `drift` (`elapsed` [s] after the
    /// origin of time, `1 - gain*(1 - exp(-elapsed/time_constant))`) on the Coulomb and
    /// static friction levels; `None` for the other effects.
    #[inline]
    pub fn friction_factor(&self, x: f64, elapsed: f64) -> Option<f64> {
        match self {
            Effect::PositionFriction { positions, scale } => {
                Some(interp_clamped(positions, scale, x))
            }
            Effect::Drift {
                gain,
                time_constant,
            } => Some(drift_factor(*gain, *time_constant, elapsed)),
            _ => None,
        }
    }
}

/// `1 - gain*(1 - exp(-elapsed/time_constant))`.
#[inline(always)]
pub(crate) fn drift_factor(gain: f64, time_constant: f64, elapsed: f64) -> f64 {
    1.0 - gain * (1.0 - (-elapsed / time_constant).exp())
}

/// Linear interpolation in `(xp, fp)`, constant beyond the ends (`xp` increasing).
fn interp_clamped(xp: &[f64], fp: &[f64], x: f64) -> f64 {
    let n = xp.len();
    if x <= xp[0] {
        return fp[0];
    }
    if x >= xp[n - 1] {
        return fp[n - 1];
    }
    // binary search: first index with xp[j] > x
    let j = xp.partition_point(|&p| p <= x);
    let (x0, x1) = (xp[j - 1], xp[j]);
    fp[j - 1] + (fp[j] - fp[j - 1]) * (x - x0) / (x1 - x0)
}

/// The effect forces of a model gathered for a simulator's inner loop: the springs and
/// offsets as one `a*x + b`, the cogging and gravity terms in one list, the drags as one
/// coefficient. The sum of [`Effect::add_force`] over the effects, in another order.
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct EffectForces {
    /// Sum of the spring stiffnesses [N/m].
    lin_a: f64,
    /// Sum of the offsets and of `-stiffness*x0` [N].
    lin_b: f64,
    /// Every cogging and gravity term, in the order of the effects.
    sines: Vec<Sine>,
    /// Sum of the drag coefficients (0 without drag).
    drag: f64,
}

impl EffectForces {
    pub(crate) fn new(effects: &[Effect]) -> Self {
        let mut f = EffectForces::default();
        for e in effects {
            match e {
                Effect::Cogging { .. } | Effect::Gravity { .. } => f.sines.extend(e.sines()),
                Effect::Spring { stiffness, x0 } => {
                    f.lin_a += stiffness;
                    f.lin_b -= stiffness * x0;
                }
                Effect::Offset { force } => f.lin_b += force,
                Effect::Drag { coefficient } => f.drag += coefficient,
                _ => {}
            }
        }
        f
    }

    /// The springs and offsets at `x`.
    #[inline(always)]
    pub(crate) fn linear(&self, x: f64) -> f64 {
        self.lin_a * x + self.lin_b
    }

    /// `f` plus the cogging, gravity and drag forces at `(x, v)`.
    #[inline(always)]
    pub(crate) fn add_nonlinear(&self, mut f: f64, x: f64, v: f64) -> f64 {
        for s in &self.sines {
            f += s.at(x);
        }
        if self.drag != 0.0 {
            f += self.drag * v.abs() * v;
        }
        f
    }
}

/// The friction factors of a model gathered for a simulator's inner loop: its
/// `position_friction`s, then its `drift`s.
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct FrictionScale {
    factors: Vec<Effect>,
}

impl FrictionScale {
    pub(crate) fn new(effects: &[Effect]) -> Self {
        let of = |pick: fn(&Effect) -> bool| effects.iter().filter(move |e| pick(e)).cloned();
        let mut factors: Vec<Effect> =
            of(|e| matches!(e, Effect::PositionFriction { .. })).collect();
        factors.extend(of(|e| matches!(e, Effect::Drift { .. })));
        FrictionScale { factors }
    }

    /// Whether the model scales no friction level.
    pub(crate) fn is_empty(&self) -> bool {
        self.factors.is_empty()
    }

    /// The product of the factors at position `x` [m], `elapsed` [s] after the origin.
    #[inline(always)]
    pub(crate) fn at(&self, x: f64, elapsed: f64) -> f64 {
        let mut s = 1.0;
        for e in &self.factors {
            if let Some(f) = e.friction_factor(x, elapsed) {
                s *= f;
            }
        }
        s
    }
}

/// What a model's actuator does between the current and the force on the motor, and
/// the friction that force adds, gathered once for the simulator and the inverse
/// dynamics.
///
/// The order is fixed: on the current the `deadband` first, then the `current_limit`'s
/// clip; then `K_F` (and the `current_lag` of the force, where a model has one); the
/// `force_ripple` last, at the motor's position: `F_m = ripple(x)*lag(K_F*clip(db(i)))`,
/// without a lag `K_F*ripple(x)*clip(db(i))`. A `load_friction` then raises the friction
/// levels by `coefficient*|F_m|`. The recorded current is the one before all of them
/// (the command, or a current loop's actual current).
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct Actuator {
    /// `deadband` half-width [A] (the last of the model's).
    pub(crate) deadband: Option<f64>,
    /// `current_limit` [A].
    pub(crate) limit: Option<f64>,
    /// The `force_ripple` terms `amplitude*sin(2*pi*x/pitch + phase)`, in the order of
    /// the effects (several add up: `1 + sum_k amplitude_k*sin(...)`).
    pub(crate) ripple: Vec<Sine>,
    /// `load_friction` coefficient [-].
    pub(crate) load: Option<f64>,
}

impl Actuator {
    pub(crate) fn new(effects: &[Effect]) -> Self {
        let mut a = Actuator::default();
        for e in effects {
            match e {
                Effect::Deadband { current } => a.deadband = Some(*current),
                Effect::CurrentLimit { current } => a.limit = Some(*current),
                Effect::ForceRipple {
                    amplitude,
                    pitch,
                    phase,
                } => a.ripple.push(Sine {
                    amplitude: *amplitude,
                    wavenumber: 2.0 * PI / pitch,
                    phase: *phase,
                }),
                Effect::LoadFriction { coefficient } => a.load = Some(*coefficient),
                _ => {}
            }
        }
        a
    }

    /// The current that produces force: `i` through the dead band (`i - c` above `c`,
    /// `i + c` below `-c`, else 0), then clipped to `+-limit`.
    #[inline(always)]
    pub(crate) fn current(&self, i: f64) -> f64 {
        let i = match self.deadband {
            Some(c) if i > c => i - c,
            Some(c) if i < -c => i + c,
            Some(_) => 0.0,
            None => i,
        };
        match self.limit {
            Some(l) => i.clamp(-l, l),
            None => i,
        }
    }

    /// The motor force `f` times the ripple factor `1 + sum_k A_k*sin(w_k*x + phase_k)`
    /// at the motor's position `x` (`f` itself without a `force_ripple`).
    #[inline(always)]
    pub(crate) fn ripple(&self, f: f64, x: f64) -> f64 {
        if self.ripple.is_empty() {
            return f;
        }
        let mut r = 1.0;
        for s in &self.ripple {
            r += s.at(x);
        }
        f * r
    }

    /// The rise `coefficient*|f|` [N] of the friction levels under the motor force `f`
    /// (0 without a `load_friction`).
    #[inline(always)]
    pub(crate) fn level(&self, f: f64) -> f64 {
        match self.load {
            Some(c) => c * f.abs(),
            None => 0.0,
        }
    }
}

/// `g(v)` of a static set with both levels raised by `level` [N] (a `load_friction`):
/// `(fc + level) + (fs - fc)*exp(-p)`, `p = (v/vs)^2` computed as [`StaticSet::g`] does
/// (`exponent` `None`) or `|v/vs|^exponent` as [`StaticSet::g_shaped`]; equal to them
/// at `level == 0`.
#[inline(always)]
pub(crate) fn g_loaded(set: &StaticSet<f64>, v: f64, level: f64, exponent: Option<f64>) -> f64 {
    let e = match exponent {
        None => {
            let r = v / set.vs;
            (-(r * r)).exp()
        }
        Some(n) => (-((v / set.vs).abs().powf(n))).exp(),
    };
    (set.fc + level) + (set.fs - set.fc) * e
}

/// `(g, F, zdot)` of [`LugreParams::eval`] (or `eval_shaped` with `exponent`) with the
/// levels raised by `level` [N]: `g = scale*g_loaded(v)`.
#[inline(always)]
pub(crate) fn eval_loaded(
    p: &LugreParams<f64>,
    z: f64,
    v: f64,
    scale: f64,
    level: f64,
    exponent: Option<f64>,
) -> (f64, f64, f64) {
    let s = p.set(v);
    let g = scale * g_loaded(s, v, level, exponent);
    let zdot = v - p.sigma0 * v.abs() * z / g;
    let f = p.sigma0 * z + p.sigma1 * zdot + s.sigma2 * v;
    (g, f, zdot)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn effects() -> Vec<Effect> {
        vec![
            Effect::Spring {
                stiffness: 350.0,
                x0: 0.013,
            },
            Effect::Cogging {
                amplitude: 2.5,
                pitch: 0.032,
                phase: 0.3,
                harmonics: vec![(0.7, -1.1), (0.2, 2.0)],
            },
            Effect::Offset { force: -1.75 },
            Effect::Drag { coefficient: 40.0 },
            Effect::Mass { delta: 3.0 },
            Effect::Spring {
                stiffness: -20.0,
                x0: -0.1,
            },
            Effect::Drag { coefficient: 5.0 },
            Effect::Gravity {
                torque: 4.0,
                phase: -0.6,
            },
        ]
    }

    #[test]
    fn gathered_forces_are_the_sum_of_the_effects() {
        let es = effects();
        let g = EffectForces::new(&es);
        for k in 0..200 {
            let x = -0.2 + 0.002 * k as f64;
            let v = 1.3 * (0.37 * k as f64).sin();
            let each = es.iter().fold(0.0, |f, e| e.add_force(f, x, v));
            let all = g.add_nonlinear(g.linear(x), x, v);
            assert!(
                (each - all).abs() <= 1e-12 * each.abs().max(1.0),
                "{each} {all}"
            );
        }
        assert_eq!(es[4].force(0.1, 0.2), 0.0);
        assert!(!es[4].is_force() && es[1].is_force());
    }

    #[test]
    fn names_in_the_order_of_the_variants() {
        let every = [
            r#"{"effect": "cogging", "amplitude": 1, "pitch": 0.03}"#,
            r#"{"effect": "spring", "stiffness": 1}"#,
            r#"{"effect": "offset", "force": 1}"#,
            r#"{"effect": "position_friction", "positions": [0], "scale": [1]}"#,
            r#"{"effect": "drift", "gain": 0.1, "time_constant": 1}"#,
            r#"{"effect": "mass", "delta": 1}"#,
            r#"{"effect": "delay", "seconds": 0.001}"#,
            r#"{"effect": "current_lag", "bandwidth": 100}"#,
            r#"{"effect": "resonance", "frequency": 20, "damping_ratio": 0.1, "load_fraction": 0.5}"#,
            r#"{"effect": "deadband", "current": 0.1}"#,
            r#"{"effect": "drag", "coefficient": 1}"#,
            r#"{"effect": "stribeck_shape", "exponent": 1.5}"#,
            r#"{"effect": "gravity", "torque": 3.5, "phase": 0.2}"#,
            r#"{"effect": "load_friction", "coefficient": 0.05}"#,
            r#"{"effect": "force_ripple", "amplitude": 0.02, "pitch": 0.03, "phase": 1.0}"#,
            r#"{"effect": "current_limit", "current": 4.0}"#,
        ];
        assert_eq!(every.len(), EFFECT_NAMES.len());
        for (text, name) in every.iter().zip(EFFECT_NAMES) {
            let e = parse_effect(&serde_json::from_str(text).unwrap(), "effects[0]").unwrap();
            assert_eq!(e.name(), name);
        }
        let err = parse_effect(&serde_json::json!({"effect": "magic"}), "effects[2]");
        let msg = err.unwrap_err().to_string();
        assert!(msg.contains("effects[2].effect"), "{msg}");
        assert!(
            msg.contains(
                "use one of cogging, spring, offset, position_friction, drift, mass, \
                 delay, current_lag, resonance, deadband, drag, stribeck_shape, gravity, \
                 load_friction, force_ripple, current_limit"
            ),
            "{msg}"
        );
    }

    #[test]
    fn cogging_terms() {
        let s: Vec<Sine> = effects()[1].sines().collect();
        assert_eq!(s.len(), 3);
        let w = 2.0 * PI / 0.032;
        assert_eq!(s[0].wavenumber, w);
        assert_eq!(s[2].wavenumber, 3.0 * w);
        assert_eq!(effects()[0].sines().count(), 0);
    }

    #[test]
    fn friction_factors() {
        let p = Effect::PositionFriction {
            positions: vec![0.0, 0.1],
            scale: vec![1.0, 2.0],
        };
        let d = Effect::Drift {
            gain: 0.2,
            time_constant: 10.0,
        };
        assert_eq!(p.friction_factor(-1.0, 0.0), Some(1.0));
        assert_eq!(p.friction_factor(0.05, 0.0), Some(1.5));
        assert_eq!(p.friction_factor(1.0, 0.0), Some(2.0));
        assert_eq!(d.friction_factor(0.0, 0.0), Some(1.0));
        assert!((d.friction_factor(0.0, 1e9).unwrap() - 0.8).abs() < 1e-15);
        assert_eq!(
            Effect::Offset { force: 1.0 }.friction_factor(0.0, 0.0),
            None
        );
        let s = FrictionScale::new(&[d.clone(), Effect::Mass { delta: 1.0 }, p.clone()]);
        assert_eq!(s.factors, vec![p, d]);
        assert!(!s.is_empty() && FrictionScale::new(&[]).is_empty());
    }

    #[test]
    fn gravity_is_a_sine_of_the_angle() {
        let g = Effect::Gravity {
            torque: 4.0,
            phase: -0.6,
        };
        assert!(g.is_force());
        for x in [-3.0, -0.6, 0.0, 0.97, 2.5] {
            let want = 4.0 * f64::sin(x - 0.6);
            assert_eq!(g.force(x, 0.3).to_bits(), want.to_bits(), "{x}");
        }
        assert_eq!(g.force(0.6, 0.0), 0.0);
        assert_eq!(g.force(0.6 + PI / 2.0, 0.0), 4.0);
        let s: Vec<Sine> = g.sines().collect();
        assert_eq!(s.len(), 1);
        assert_eq!(
            (s[0].amplitude, s[0].wavenumber, s[0].phase),
            (4.0, 1.0, -0.6)
        );
    }

    #[test]
    fn new_effects_reject_bad_parameters_by_path() {
        for (text, path) in [
            (
                r#"{"effect": "force_ripple", "amplitude": 1.0, "pitch": 0.03}"#,
                "effects[3].amplitude",
            ),
            (
                r#"{"effect": "force_ripple", "amplitude": -1.5, "pitch": 0.03}"#,
                "effects[3].amplitude",
            ),
            (
                r#"{"effect": "force_ripple", "amplitude": 0.1, "pitch": 0}"#,
                "effects[3].pitch",
            ),
            (
                r#"{"effect": "load_friction", "coefficient": -0.01}"#,
                "effects[3].coefficient",
            ),
            (
                r#"{"effect": "current_limit", "current": 0}"#,
                "effects[3].current",
            ),
            (
                r#"{"effect": "current_limit", "current": -2}"#,
                "effects[3].current",
            ),
        ] {
            let e = parse_effect(&serde_json::from_str(text).unwrap(), "effects[3]").unwrap_err();
            assert!(
                matches!(&e, Error::Parameter { name, .. } if name == path),
                "{text}: {e}"
            );
        }
        for (text, path) in [
            (r#"{"effect": "gravity", "phase": 1}"#, "effects[3].torque"),
            (
                r#"{"effect": "force_ripple", "pitch": 0.1}"#,
                "effects[3].amplitude",
            ),
            (
                r#"{"effect": "current_limit", "current": "4 A"}"#,
                "effects[3].current",
            ),
        ] {
            let e = parse_effect(&serde_json::from_str(text).unwrap(), "effects[3]").unwrap_err();
            assert!(
                matches!(&e, Error::Model { path: p, .. } if p == path),
                "{text}: {e}"
            );
        }
        // the phases are optional, as a cogging's
        let r = r#"{"effect": "force_ripple", "amplitude": -0.999, "pitch": 0.1}"#;
        let e = parse_effect(&serde_json::from_str(r).unwrap(), "effects[0]").unwrap();
        assert_eq!(
            e,
            Effect::ForceRipple {
                amplitude: -0.999,
                pitch: 0.1,
                phase: 0.0
            }
        );
    }

    #[test]
    fn the_actuator_clips_after_the_dead_band_and_ripples_last() {
        let none = Actuator::new(&[Effect::Mass { delta: 1.0 }]);
        assert_eq!(none, Actuator::default());
        assert_eq!(
            (none.current(-7.5), none.ripple(3.0, 0.2), none.level(-9.0)),
            (-7.5, 3.0, 0.0)
        );
        let a = Actuator::new(&[
            Effect::CurrentLimit { current: 2.0 },
            Effect::Deadband { current: 0.5 },
            Effect::ForceRipple {
                amplitude: 0.1,
                pitch: 0.04,
                phase: 0.25,
            },
            Effect::LoadFriction { coefficient: 0.2 },
        ]);
        // dead band first (0.5 A off |i|), then the clip at 2 A, whatever their order in
        // the model
        for (i, want) in [
            (0.0, 0.0),
            (0.4, 0.0),
            (-0.5, 0.0),
            (1.5, 1.0),
            (-2.0, -1.5),
            (2.5, 2.0),
            (-40.0, -2.0),
        ] {
            assert_eq!(a.current(i), want, "{i}");
        }
        let w = 2.0 * PI / 0.04;
        for x in [-0.3, 0.0, 0.011, 0.5] {
            let want = 50.0 * (1.0 + 0.1 * (w * x + 0.25).sin());
            assert_eq!(a.ripple(50.0, x).to_bits(), want.to_bits(), "{x}");
        }
        // at the ripple's crest and trough
        let crest = (PI / 2.0 - 0.25) / w;
        assert!((a.ripple(50.0, crest) - 55.0).abs() < 1e-12);
        assert!((a.ripple(50.0, crest + 0.02) - 45.0).abs() < 1e-12);
        assert_eq!((a.level(-30.0), a.level(30.0)), (6.0, 6.0));
        // two ripples add up in the factor
        let two = Actuator::new(&[
            Effect::ForceRipple {
                amplitude: 0.1,
                pitch: 0.04,
                phase: 0.0,
            },
            Effect::ForceRipple {
                amplitude: 0.05,
                pitch: 0.01,
                phase: 0.0,
            },
        ]);
        let x = 0.01 / 4.0; // both sines at their crest
        assert!((two.ripple(10.0, x) - 10.0 * (1.0 + 0.1 * (PI / 8.0).sin() + 0.05)).abs() < 1e-12);
    }

    #[test]
    fn load_friction_raises_both_levels() {
        let set = StaticSet::new(28.7, 60.2, 332.5, 0.01).unwrap();
        let p = LugreParams::new(1e5, 31.62, set, set).unwrap();
        for v in [0.0, 1e-3, -0.004, 0.01, 0.2, -5.0] {
            for ex in [None, Some(0.8), Some(2.0)] {
                let plain = match ex {
                    None => set.g(v),
                    Some(e) => set.g_shaped(v, e),
                };
                assert_eq!(g_loaded(&set, v, 0.0, ex).to_bits(), plain.to_bits());
                // fc and fs raised by 7.5 N: the same curve, 7.5 N higher
                let up = StaticSet::new(28.7 + 7.5, 60.2 + 7.5, 332.5, 0.01).unwrap();
                let want = match ex {
                    None => up.g(v),
                    Some(e) => up.g_shaped(v, e),
                };
                assert!(
                    (g_loaded(&set, v, 7.5, ex) - want).abs() < 1e-12,
                    "{v} {ex:?}"
                );
                let (g, f, zdot) = eval_loaded(&p, 1e-4, v, 1.2, 7.5, ex);
                assert_eq!(g, 1.2 * g_loaded(&set, v, 7.5, ex));
                assert_eq!(zdot, v - 1e5 * v.abs() * 1e-4 / g);
                assert_eq!(f, 1e5 * 1e-4 + 31.62 * zdot + 332.5 * v);
            }
        }
        assert_eq!(g_loaded(&set, 0.0, 7.5, None), 60.2 + 7.5);
        assert_eq!(g_loaded(&set, 1.0, 7.5, None), 28.7 + 7.5);
    }
}
