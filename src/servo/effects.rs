//! The effects of the model vocabulary: their names and parser, and what they do to the
//! moving body, defined once for the simulator ([`super::sim`]) and the inverse dynamics
//! ([`crate::inverse`]): the force of a `cogging`, `spring`, `offset` or `drag` at
//! `(x, v)`, and the factor of a `position_friction` or `drift` on the friction levels.
//!
//! The simulator adds the forces up in its own order, gathered once per run
//! (`EffectForces`: the springs and offsets as one `a*x + b`, the drags as one
//! coefficient), the inverse dynamics effect by effect ([`Effect::add_force`]); the
//! two sums agree to rounding, and each is the order its NumPy twin repeats to the last
//! bit (`lugre.reference`). Likewise the inverse dynamics interpolates a
//! `position_friction` over the whole record as `numpy.interp` does.

use super::model::{get, join, nonneg, num, num_list, opt_num, positive, Effect};
use crate::error::{Error, Result};
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

/// Every effect name of the model file (`"effect": name`), in the order [`Effect`]
/// declares its variants (the CONTRACT's).
pub const EFFECT_NAMES: [&str; 12] = [
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
    Ok(match kind {
        COGGING => {
            let harmonics = match e.get("harmonics") {
                None | Some(Value::Null) => Vec::new(),
                Some(h) => {
                    let hp = p("harmonics");
                    let a = h.as_array().ok_or_else(|| {
                        Error::model(&hp, "must be a list of [amplitude, phase] pairs")
                    })?;
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
                        .collect::<Result<Vec<_>>>()?
                }
            };
            Effect::Cogging {
                amplitude: n("amplitude")?,
                pitch: positive(n("pitch")?, &p("pitch"))?,
                phase: opt_num(e, "phase", path)?.unwrap_or(0.0),
                harmonics,
            }
        }
        SPRING => Effect::Spring {
            stiffness: n("stiffness")?,
            x0: opt_num(e, "x0", path)?.unwrap_or(0.0),
        },
        OFFSET => Effect::Offset { force: n("force")? },
        POSITION_FRICTION => {
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
            Effect::PositionFriction { positions, scale }
        }
        DRIFT => {
            let gain = n("gain")?;
            if gain >= 1.0 {
                return Err(Error::parameter(
                    &p("gain"),
                    gain,
                    "must be below 1 (friction would vanish or turn negative)",
                ));
            }
            Effect::Drift {
                gain,
                time_constant: positive(n("time_constant")?, &p("time_constant"))?,
            }
        }
        MASS | INERTIA => Effect::Mass { delta: n("delta")? },
        DELAY => Effect::Delay {
            seconds: nonneg(n("seconds")?, &p("seconds"))?,
        },
        CURRENT_LAG => Effect::CurrentLag {
            bandwidth_hz: positive(n("bandwidth")?, &p("bandwidth"))?,
        },
        RESONANCE => {
            let frequency_hz = positive(n("frequency")?, &p("frequency"))?;
            let damping_ratio = nonneg(n("damping_ratio")?, &p("damping_ratio"))?;
            let load_fraction = n("load_fraction")?;
            if !(load_fraction > 0.0 && load_fraction < 1.0) {
                return Err(Error::parameter(
                    &p("load_fraction"),
                    load_fraction,
                    "must lie strictly between 0 and 1 (the load's share of the total mass)",
                ));
            }
            Effect::Resonance {
                frequency_hz,
                damping_ratio,
                load_fraction,
            }
        }
        DEADBAND => Effect::Deadband {
            current: nonneg(n("current")?, &p("current"))?,
        },
        DRAG => Effect::Drag {
            coefficient: nonneg(n("coefficient")?, &p("coefficient"))?,
        },
        STRIBECK_SHAPE => Effect::StribeckShape {
            exponent: positive(n("exponent")?, &p("exponent"))?,
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
    /// none for the other effects.
    pub fn sines(&self) -> impl Iterator<Item = Sine> + '_ {
        let (base, harmonics) = match self {
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
    /// `drag`).
    pub fn is_force(&self) -> bool {
        matches!(
            self,
            Effect::Cogging { .. }
                | Effect::Spring { .. }
                | Effect::Offset { .. }
                | Effect::Drag { .. }
        )
    }

    /// `acc` plus the force [N] of the effect on the moving body at position `x` [m] and
    /// velocity `v` [m/s], its terms added one by one (a cogging's harmonics in turn);
    /// `acc` itself for an effect that is no force ([`Effect::is_force`]).
    ///
    /// `cogging`: `sum_k A_k*sin(k*2*pi*x/pitch + phase_k)`; `spring`: `k*(x - x0)`;
    /// `offset`: the constant force; `drag`: `coefficient*|v|*v`.
    #[inline]
    pub fn add_force(&self, acc: f64, x: f64, v: f64) -> f64 {
        match self {
            Effect::Cogging { .. } => self.sines().fold(acc, |f, s| f + s.at(x)),
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
/// offsets as one `a*x + b`, the cogging terms in one list, the drags as one
/// coefficient. The sum of [`Effect::add_force`] over the effects, in another order.
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct EffectForces {
    /// Sum of the spring stiffnesses [N/m].
    lin_a: f64,
    /// Sum of the offsets and of `-stiffness*x0` [N].
    lin_b: f64,
    /// Every cogging term, in the order of the effects.
    sines: Vec<Sine>,
    /// Sum of the drag coefficients (0 without drag).
    drag: f64,
}

impl EffectForces {
    pub(crate) fn new(effects: &[Effect]) -> Self {
        let mut f = EffectForces::default();
        for e in effects {
            match e {
                Effect::Cogging { .. } => f.sines.extend(e.sines()),
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

    /// `f` plus the cogging and drag forces at `(x, v)`.
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
                          delay, current_lag, resonance, deadband, drag, stribeck_shape"
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
}
