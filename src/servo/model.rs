//! The axis model: mass, force constant, current loop, LuGre friction, extra physics
//! (the CONTRACT vocabulary of effects) and the controller. Read from the model JSON
//! of `docs/DESIGN.md`; every field is validated with a message naming its path.

use crate::error::{Error, Result};
use crate::friction::{LugreParams, StaticSet};
use serde_json::Value;

/// Current loop between the command and the actual current.
#[derive(Debug, Clone, PartialEq)]
pub enum CurrentLoop {
    /// First-order lag with the given bandwidth [Hz].
    FirstOrder {
        /// -3 dB bandwidth [Hz].
        bandwidth_hz: f64,
    },
    /// R-L winding with back-EMF under a continuous PI current controller.
    Rl {
        /// Winding resistance [Ohm].
        resistance: f64,
        /// Winding inductance [H].
        inductance: f64,
        /// Back-EMF constant [V s/m].
        back_emf: f64,
        /// Proportional gain [V/A].
        kp: f64,
        /// Integral gain [V/(A s)].
        ki: f64,
    },
}

/// Whether the axis moves along a line or turns (CONTRACT, "Rotary axes").
///
/// The equations are the same; only the units differ: a linear axis speaks m, N, kg and
/// N/A, a rotary one rad, N m, kg m^2 and N m/A. The core keeps one set of fields
/// (`mass` holds a rotary axis's inertia, `force_constant` its torque constant).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum AxisKind {
    /// A linear axis (`"kind": "linear"`, the default): `mass`, `force_constant`.
    #[default]
    Linear,
    /// A rotary axis (`"kind": "rotary"`): `inertia`, `torque_constant`.
    Rotary,
}

/// The axis.
#[derive(Debug, Clone, PartialEq)]
pub struct Axis {
    /// Linear or rotary.
    pub kind: AxisKind,
    /// Moving mass [kg], or a rotary axis's inertia [kg m^2].
    pub mass: f64,
    /// Force constant K_F [N/A], or a rotary axis's torque constant [N m/A].
    pub force_constant: f64,
    /// Optional current loop.
    pub current_loop: Option<CurrentLoop>,
    /// Optional current limit [A].
    pub current_limit: Option<f64>,
}

/// Physics beyond the LuGre axis (CONTRACT vocabulary).
#[derive(Debug, Clone, PartialEq)]
pub enum Effect {
    /// `F = A*sin(2*pi*x/pitch + phase) + sum_k A_k*sin(k*2*pi*x/pitch + phase_k)`.
    Cogging {
        /// Base amplitude [N].
        amplitude: f64,
        /// Pitch [m].
        pitch: f64,
        /// Phase [rad].
        phase: f64,
        /// `(amplitude, phase)` of harmonics 2, 3, ...
        harmonics: Vec<(f64, f64)>,
    },
    /// `F = k*(x - x0)`.
    Spring {
        /// Stiffness [N/m].
        stiffness: f64,
        /// Rest position [m].
        x0: f64,
    },
    /// Constant force [N].
    Offset {
        /// Force [N].
        force: f64,
    },
    /// fc and fs scaled by a piecewise-linear function of position.
    PositionFriction {
        /// Breakpoints [m], increasing.
        positions: Vec<f64>,
        /// Scale at each breakpoint.
        scale: Vec<f64>,
    },
    /// fc and fs scaled by `1 - gain*(1 - exp(-t/time_constant))`.
    Drift {
        /// Relative change at the end of warm-up.
        gain: f64,
        /// Time constant [s].
        time_constant: f64,
    },
    /// Extra moving mass [kg].
    Mass {
        /// Mass change [kg].
        delta: f64,
    },
    /// The force acts `seconds` after the current command.
    Delay {
        /// Dead time [s].
        seconds: f64,
    },
    /// The force follows the current through a first-order lag.
    CurrentLag {
        /// Bandwidth [Hz].
        bandwidth_hz: f64,
    },
    /// Two masses joined by a spring-damper: the motor `(1 - r)*mass` (driven, measured)
    /// and the load `r*mass` (friction and the other effects' forces act on it), with
    /// `k = r*mass*(2*pi*frequency)^2` and `c = 2*damping_ratio*sqrt(k*r*mass)`.
    Resonance {
        /// Natural frequency of the load with the motor held [Hz].
        frequency_hz: f64,
        /// Damping ratio of that mode [-].
        damping_ratio: f64,
        /// Share `r` of the total mass on the load side, `0 < r < 1`.
        load_fraction: f64,
    },
    /// Motor force `K_F*sign(i)*max(|i| - current, 0)`.
    Deadband {
        /// Half-width of the dead band [A].
        current: f64,
    },
    /// Force `coefficient*|v|*v` opposing motion.
    Drag {
        /// [N s^2/m^2]
        coefficient: f64,
    },
    /// `g(v) = fc + (fs - fc)*exp(-|v/vs|^exponent)` in place of exponent 2.
    StribeckShape {
        /// Exponent of the Stribeck curve [-].
        exponent: f64,
    },
    /// `F = torque*sin(x + phase)` on the load of a rotary axis (a weight on a joint; on a
    /// linear axis gravity is an `Offset`).
    Gravity {
        /// Largest torque of the weight [N m].
        torque: f64,
        /// Angle [rad]: the torque is largest at `x = pi/2 - phase`.
        phase: f64,
    },
    /// fc and fs of both directions raised by `coefficient*|F_m|`, `F_m` the motor force
    /// acting (after the actuator's dead band, limit, lag and ripple).
    LoadFriction {
        /// Friction per newton of motor force [-].
        coefficient: f64,
    },
    /// Motor force `K_F*i*(1 + amplitude*sin(2*pi*x/pitch + phase))` (force-constant
    /// ripple), at the motor's position.
    ForceRipple {
        /// Relative amplitude [-], `|amplitude| < 1`.
        amplitude: f64,
        /// Pitch [m].
        pitch: f64,
        /// Phase [rad].
        phase: f64,
    },
    /// Motor force `K_F*clip(i, -current, current)`: the amplifier saturates (the
    /// recorded current is the command). Not the axis's `current_limit`, which clips the
    /// controller's command itself.
    CurrentLimit {
        /// Largest current that produces force [A].
        current: f64,
    },
}

/// Feed-forward law.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FeedforwardKind {
    /// Stribeck curve of the reference velocity.
    Static,
    /// LuGre observer driven by the reference velocity.
    Lugre,
}

/// Friction feed-forward with its own (identified) friction parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct Feedforward {
    /// Which law.
    pub kind: FeedforwardKind,
    /// Friction used for compensation.
    pub friction: LugreParams<f64>,
}

/// Control law.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ControlLaw {
    /// PID on position (CONTRACT `pid`, seed paper eq. 12).
    Pid {
        /// [N/m]
        kp: f64,
        /// [N/(m s)]
        ki: f64,
        /// [N s/m]
        kd: f64,
    },
    /// PI on speed.
    PiSpeed {
        /// [N s/m]
        kp: f64,
        /// [N/m]
        ki: f64,
    },
}

/// Digital controller.
#[derive(Debug, Clone, PartialEq)]
pub struct Controller {
    /// The law.
    pub law: ControlLaw,
    /// Update rate [Hz].
    pub rate_hz: f64,
    /// Optional friction feed-forward.
    pub feedforward: Option<Feedforward>,
}

/// A complete model.
#[derive(Debug, Clone, PartialEq)]
pub struct Model {
    /// The axis.
    pub axis: Axis,
    /// Its friction.
    pub friction: LugreParams<f64>,
    /// Extra physics.
    pub effects: Vec<Effect>,
    /// Optional controller.
    pub controller: Option<Controller>,
}

pub(super) fn get<'a>(obj: &'a Value, key: &str, path: &str) -> Result<&'a Value> {
    obj.get(key).ok_or_else(|| {
        Error::model(
            &join(path, key),
            "is missing: add it (see docs/DESIGN.md for the model format)",
        )
    })
}

pub(super) fn join(path: &str, key: &str) -> String {
    if path.is_empty() {
        key.to_string()
    } else {
        format!("{path}.{key}")
    }
}

pub(super) fn num(obj: &Value, key: &str, path: &str) -> Result<f64> {
    let v = get(obj, key, path)?;
    as_num(v, &join(path, key))
}

fn as_num(v: &Value, path: &str) -> Result<f64> {
    let x = v
        .as_f64()
        .ok_or_else(|| Error::model(path, format!("must be a number, found {v}")))?;
    if !x.is_finite() {
        return Err(Error::parameter(path, x, "must be finite"));
    }
    Ok(x)
}

pub(super) fn opt_num(obj: &Value, key: &str, path: &str) -> Result<Option<f64>> {
    match obj.get(key) {
        None | Some(Value::Null) => Ok(None),
        Some(v) => as_num(v, &join(path, key)).map(Some),
    }
}

pub(super) fn positive(x: f64, path: &str) -> Result<f64> {
    if x > 0.0 {
        Ok(x)
    } else {
        Err(Error::parameter(path, x, "must be greater than zero"))
    }
}

pub(super) fn nonneg(x: f64, path: &str) -> Result<f64> {
    if x >= 0.0 {
        Ok(x)
    } else {
        Err(Error::parameter(path, x, "must be zero or greater"))
    }
}

pub(super) fn num_list(v: &Value, path: &str) -> Result<Vec<f64>> {
    let a = v
        .as_array()
        .ok_or_else(|| Error::model(path, "must be a list of numbers"))?;
    a.iter()
        .enumerate()
        .map(|(k, x)| as_num(x, &format!("{path}[{k}]")))
        .collect()
}

/// Parse the `friction` object.
pub fn parse_friction(f: &Value, path: &str) -> Result<LugreParams<f64>> {
    if let Some(m) = f.get("model") {
        if m.as_str() != Some("lugre") {
            return Err(Error::model(
                &join(path, "model"),
                format!("is {m}; only \"lugre\" is supported"),
            ));
        }
    }
    let set = |dir: &str| -> Result<StaticSet<f64>> {
        let p = join(path, dir);
        let s = get(f, dir, path)?;
        Ok(StaticSet {
            fc: num(s, "fc", &p)?,
            fs: num(s, "fs", &p)?,
            sigma2: num(s, "sigma2", &p)?,
            vs: num(s, "vs", &p)?,
        })
    };
    let p = LugreParams {
        sigma0: num(f, "sigma0", path)?,
        sigma1: num(f, "sigma1", path)?,
        positive: set("positive")?,
        negative: set("negative")?,
    };
    p.validate().map_err(|e| {
        let mut err: Error = e.into();
        if let Error::Parameter { name, .. } = &mut err {
            if path != "friction" {
                *name = name.replacen("friction", path, 1);
            }
        }
        err
    })?;
    Ok(p)
}

impl Model {
    /// The seed paper's linear-motor axis (m = 25 kg, K_F = 25 N/A, LuGre parameters of
    /// its Tables 1 and 2) under the CONTRACT's PID (kp 5e4, ki 5e5, kd 1500 at 10 kHz);
    /// the twin of Python's `Model.paper()`.
    ///
    /// ```
    /// let m = lugre::servo::Model::paper();
    /// assert_eq!(m.friction.positive.fs, 60.2);
    /// ```
    pub fn paper() -> Model {
        let set = |fc, fs, sigma2| StaticSet {
            fc,
            fs,
            sigma2,
            vs: 0.01,
        };
        Model {
            axis: Axis {
                kind: AxisKind::Linear,
                mass: 25.0,
                force_constant: 25.0,
                current_loop: None,
                current_limit: None,
            },
            friction: LugreParams {
                sigma0: 1e5,
                sigma1: 31.62,
                positive: set(28.7, 60.2, 332.5),
                negative: set(28.5, 60.1, 333.0),
            },
            effects: Vec::new(),
            controller: Some(Controller {
                law: ControlLaw::Pid {
                    kp: 5e4,
                    ki: 5e5,
                    kd: 1500.0,
                },
                rate_hz: 1e4,
                feedforward: None,
            }),
        }
    }

    /// Parse and validate a model from its JSON text.
    pub fn from_json(text: &str) -> Result<Model> {
        let v: Value = serde_json::from_str(text)
            .map_err(|e| Error::model("(file)", format!("is not valid JSON: {e}")))?;
        Model::from_value(&v)
    }

    /// Parse and validate a model from a JSON value.
    pub fn from_value(v: &Value) -> Result<Model> {
        let a = get(v, "axis", "")?;
        let cl = match a.get("current_loop") {
            None | Some(Value::Null) => None,
            Some(c) => {
                let path = "axis.current_loop";
                if c.get("inductance").is_some() || c.get("resistance").is_some() {
                    let r = nonneg(num(c, "resistance", path)?, "axis.current_loop.resistance")?;
                    let l = positive(num(c, "inductance", path)?, "axis.current_loop.inductance")?;
                    let ke = nonneg(
                        opt_num(c, "back_emf", path)?.unwrap_or(0.0),
                        "axis.current_loop.back_emf",
                    )?;
                    let (kp, ki) = match opt_num(c, "bandwidth_hz", path)? {
                        Some(bw) => {
                            let bw = positive(bw, "axis.current_loop.bandwidth_hz")?;
                            let w = 2.0 * core::f64::consts::PI * bw;
                            (w * l, w * r)
                        }
                        None => (
                            positive(num(c, "kp", path)?, "axis.current_loop.kp")?,
                            nonneg(num(c, "ki", path)?, "axis.current_loop.ki")?,
                        ),
                    };
                    Some(CurrentLoop::Rl {
                        resistance: r,
                        inductance: l,
                        back_emf: ke,
                        kp,
                        ki,
                    })
                } else {
                    Some(CurrentLoop::FirstOrder {
                        bandwidth_hz: positive(
                            num(c, "bandwidth_hz", path)?,
                            "axis.current_loop.bandwidth_hz",
                        )?,
                    })
                }
            }
        };
        let kind = parse_axis_kind(a)?;
        let (mass_key, constant_key) = match kind {
            AxisKind::Linear => ("mass", "force_constant"),
            AxisKind::Rotary => ("inertia", "torque_constant"),
        };
        let axis = Axis {
            kind,
            mass: positive(num(a, mass_key, "axis")?, &join("axis", mass_key))?,
            force_constant: positive(num(a, constant_key, "axis")?, &join("axis", constant_key))?,
            current_loop: cl,
            current_limit: match opt_num(a, "current_limit", "axis")? {
                None => None,
                Some(x) => Some(positive(x, "axis.current_limit")?),
            },
        };
        let friction = parse_friction(get(v, "friction", "")?, "friction")?;
        let effects = match v.get("effects") {
            None | Some(Value::Null) => Vec::new(),
            Some(e) => {
                let list = e
                    .as_array()
                    .ok_or_else(|| Error::model("effects", "must be a list"))?;
                list.iter()
                    .enumerate()
                    .map(|(k, x)| super::effects::parse_effect(x, &format!("effects[{k}]")))
                    .collect::<Result<Vec<_>>>()?
            }
        };
        check_effects(&effects, axis.kind)?;
        let dm: f64 = effects
            .iter()
            .map(|e| {
                if let Effect::Mass { delta } = e {
                    *delta
                } else {
                    0.0
                }
            })
            .sum();
        if axis.mass + dm <= 0.0 {
            return Err(Error::parameter(
                "effects.mass.delta",
                dm,
                "makes the total mass zero or negative",
            ));
        }
        let controller = match v.get("controller") {
            None | Some(Value::Null) => None,
            Some(c) => Some(parse_controller(c, &friction)?),
        };
        Ok(Model {
            axis,
            friction,
            effects,
            controller,
        })
    }

    /// Whether the axis is rotary (positions in rad, forces in N m).
    pub fn is_rotary(&self) -> bool {
        self.axis.kind == AxisKind::Rotary
    }

    /// Exponent of the plant's Stribeck curve when a `stribeck_shape` effect sets one.
    pub fn stribeck_exponent(&self) -> Option<f64> {
        self.effects.iter().find_map(|e| match e {
            Effect::StribeckShape { exponent } => Some(*exponent),
            _ => None,
        })
    }

    /// Total moving mass including `mass` effects.
    pub fn total_mass(&self) -> f64 {
        self.axis.mass
            + self
                .effects
                .iter()
                .map(|e| {
                    if let Effect::Mass { delta } = e {
                        *delta
                    } else {
                        0.0
                    }
                })
                .sum::<f64>()
    }
}

/// The rules on a model's effects as a whole (each effect is checked on its own by
/// `parse_effect`): `gravity` only on a rotary axis, then at most one each of `delay`,
/// `current_lag`, `resonance`, `stribeck_shape`, `gravity`, `load_friction` and
/// `current_limit`.
fn check_effects(effects: &[Effect], kind: AxisKind) -> Result<()> {
    if kind == AxisKind::Linear {
        if let Some(k) = effects
            .iter()
            .position(|e| matches!(e, Effect::Gravity { .. }))
        {
            return Err(Error::model(
                &format!("effects[{k}].effect"),
                "is gravity, which acts on rotary axes only: on a linear axis a weight is \
                 a constant force, give {\"effect\": \"offset\", \"force\": F} instead",
            ));
        }
    }
    let count = |pick: fn(&Effect) -> bool| effects.iter().filter(|e| pick(e)).count();
    if count(|e| matches!(e, Effect::Delay { .. })) > 1
        || count(|e| matches!(e, Effect::CurrentLag { .. })) > 1
    {
        return Err(Error::model(
            "effects",
            "holds more than one delay or current_lag: merge them into one",
        ));
    }
    if count(|e| matches!(e, Effect::Resonance { .. })) > 1
        || count(|e| matches!(e, Effect::StribeckShape { .. })) > 1
    {
        return Err(Error::model(
            "effects",
            "holds more than one resonance or stribeck_shape: keep one of each",
        ));
    }
    if count(|e| matches!(e, Effect::Gravity { .. })) > 1
        || count(|e| matches!(e, Effect::LoadFriction { .. })) > 1
        || count(|e| matches!(e, Effect::CurrentLimit { .. })) > 1
    {
        return Err(Error::model(
            "effects",
            "holds more than one gravity, load_friction or current_limit: keep one of each",
        ));
    }
    Ok(())
}

fn parse_controller(c: &Value, friction: &LugreParams<f64>) -> Result<Controller> {
    let path = "controller";
    let kind = get(c, "type", path)?
        .as_str()
        .ok_or_else(|| Error::model("controller.type", "must be a string"))?;
    let law = match kind {
        "pid" => ControlLaw::Pid {
            kp: num(c, "kp", path)?,
            ki: opt_num(c, "ki", path)?.unwrap_or(0.0),
            kd: opt_num(c, "kd", path)?.unwrap_or(0.0),
        },
        "pi_speed" => ControlLaw::PiSpeed {
            kp: num(c, "kp", path)?,
            ki: opt_num(c, "ki", path)?.unwrap_or(0.0),
        },
        other => {
            return Err(Error::model(
                "controller.type",
                format!("unknown controller \"{other}\": use \"pid\" or \"pi_speed\""),
            ))
        }
    };
    let rate_hz = positive(num(c, "rate_hz", path)?, "controller.rate_hz")?;
    let feedforward = match c.get("feedforward") {
        None | Some(Value::Null) => None,
        Some(f) => {
            let kind = match get(f, "type", "controller.feedforward")?.as_str() {
                Some("static") => FeedforwardKind::Static,
                Some("lugre") => FeedforwardKind::Lugre,
                Some("none") => {
                    return Ok(Controller {
                        law,
                        rate_hz,
                        feedforward: None,
                    })
                }
                _ => {
                    return Err(Error::model(
                        "controller.feedforward.type",
                        "must be \"static\", \"lugre\" or \"none\"",
                    ))
                }
            };
            let friction = match f.get("friction") {
                None | Some(Value::Null) => *friction,
                Some(ff) => parse_friction(ff, "controller.feedforward.friction")?,
            };
            Some(Feedforward { kind, friction })
        }
    };
    Ok(Controller {
        law,
        rate_hz,
        feedforward,
    })
}

/// The axis's `kind`: `"linear"` (the default) or `"rotary"`.
fn parse_axis_kind(a: &Value) -> Result<AxisKind> {
    match a.get("kind") {
        None | Some(Value::Null) => Ok(AxisKind::Linear),
        Some(Value::String(k)) if k == "linear" => Ok(AxisKind::Linear),
        Some(Value::String(k)) if k == "rotary" => Ok(AxisKind::Rotary),
        Some(_) => Err(Error::model(
            "axis.kind",
            "must be \"linear\" (mass, force_constant) or \"rotary\" (inertia, torque_constant)",
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const PAPER: &str = r#"{
      "axis": {"mass": 25.0, "force_constant": 25.0},
      "friction": {"model": "lugre", "sigma0": 1e5, "sigma1": 31.62,
        "positive": {"fc": 28.7, "fs": 60.2, "sigma2": 332.5, "vs": 0.01},
        "negative": {"fc": 28.5, "fs": 60.1, "sigma2": 333.0, "vs": 0.01}},
      "effects": [],
      "controller": {"type": "pid", "kp": 5e4, "ki": 5e5, "kd": 1500, "rate_hz": 10000}
    }"#;

    #[test]
    fn numbers_are_read_to_the_last_bit() {
        // serde_json's default float parser is off by one unit in the last place on
        // these (99380.907687806, 0.01008508328349048): the twins then drift apart
        let json = PAPER.replace("1e5", "99380.90768780599").replacen(
            r#""vs": 0.01}"#,
            r#""vs": 0.010085083283490481}"#,
            1,
        );
        let m = Model::from_json(&json).unwrap();
        assert_eq!(m.friction.sigma0.to_bits(), 99380.90768780599f64.to_bits());
        assert_eq!(
            m.friction.positive.vs.to_bits(),
            0.010085083283490481f64.to_bits()
        );
    }

    #[test]
    fn parses_contract_example() {
        let m = Model::from_json(PAPER).unwrap();
        assert_eq!(m, Model::paper());
        assert_eq!(m.axis.mass, 25.0);
        assert_eq!(m.friction.negative.sigma2, 333.0);
        assert!(matches!(
            m.controller.unwrap().law,
            ControlLaw::Pid { kd, .. } if kd == 1500.0
        ));
    }

    #[test]
    fn a_rotary_axis_reads_inertia_and_torque_constant() {
        let rotary = PAPER.replace(
            r#""axis": {"mass": 25.0, "force_constant": 25.0}"#,
            r#""axis": {"kind": "rotary", "inertia": 0.5, "torque_constant": 2.0}"#,
        );
        let m = Model::from_json(&rotary).unwrap();
        assert!(m.is_rotary() && !Model::paper().is_rotary());
        assert_eq!((m.axis.mass, m.axis.force_constant), (0.5, 2.0));
        let inertia = rotary.replace(
            r#""effects": []"#,
            r#""effects": [{"effect": "inertia", "delta": 0.25}]"#,
        );
        assert_eq!(Model::from_json(&inertia).unwrap().total_mass(), 0.75);
        let missing = rotary.replace(r#""inertia": 0.5, "#, "");
        let e = Model::from_json(&missing).unwrap_err().to_string();
        assert!(e.contains("axis.inertia"), "{e}");
        let odd = PAPER.replace(r#""mass": 25.0"#, r#""kind": "spherical", "mass": 25.0"#);
        let e = Model::from_json(&odd).unwrap_err().to_string();
        assert!(e.contains("axis.kind") && e.contains("rotary"), "{e}");
    }

    #[test]
    fn errors_name_the_path() {
        let bad = PAPER.replace("\"vs\": 0.01}}", "\"vs\": -0.01}}");
        let e = Model::from_json(&bad).unwrap_err().to_string();
        assert!(e.contains("friction.negative.vs"), "{e}");
        let bad = PAPER.replace("\"mass\": 25.0", "\"mass\": 0");
        let e = Model::from_json(&bad).unwrap_err().to_string();
        assert!(e.contains("axis.mass"), "{e}");
        let bad = PAPER.replace("\"effects\": []", "\"effects\": [{\"effect\": \"magic\"}]");
        let e = Model::from_json(&bad).unwrap_err().to_string();
        assert!(
            e.contains("effects[0].effect") && e.contains("magic"),
            "{e}"
        );
    }

    fn with_effects(effects: &str) -> Result<Model> {
        Model::from_json(&PAPER.replace("\"effects\": []", &format!("\"effects\": [{effects}]")))
    }

    #[test]
    fn new_effects_parse_and_validate() {
        let m = with_effects(
            r#"{"effect": "resonance", "frequency": 22, "damping_ratio": 0.04, "load_fraction": 0.75},
               {"effect": "deadband", "current": 0.15}, {"effect": "drag", "coefficient": 120},
               {"effect": "stribeck_shape", "exponent": 0.8}"#,
        )
        .unwrap();
        assert_eq!(
            m.effects[0],
            Effect::Resonance {
                frequency_hz: 22.0,
                damping_ratio: 0.04,
                load_fraction: 0.75
            }
        );
        assert_eq!(m.stribeck_exponent(), Some(0.8));
        assert_eq!(Model::paper().stribeck_exponent(), None);
        for (effects, path) in [
            (
                r#"{"effect": "drag", "coefficient": 1}, {"effect": "resonance", "frequency": 22, "damping_ratio": 0.04, "load_fraction": 1.0}"#,
                "effects[1].load_fraction",
            ),
            (
                r#"{"effect": "resonance", "frequency": -1, "damping_ratio": 0.04, "load_fraction": 0.5}"#,
                "effects[0].frequency",
            ),
            (
                r#"{"effect": "deadband", "current": -0.1}"#,
                "effects[0].current",
            ),
            (
                r#"{"effect": "stribeck_shape", "exponent": 0}"#,
                "effects[0].exponent",
            ),
            (
                r#"{"effect": "drag", "coefficient": -3}"#,
                "effects[0].coefficient",
            ),
        ] {
            let e = with_effects(effects).unwrap_err();
            assert!(
                matches!(&e, Error::Parameter { name, .. } if name == path),
                "{e}"
            );
        }
        let e = with_effects(
            r#"{"effect": "stribeck_shape", "exponent": 1}, {"effect": "stribeck_shape", "exponent": 3}"#,
        )
        .unwrap_err();
        assert!(e.to_string().contains("more than one"), "{e}");
    }

    #[test]
    fn gravity_acts_on_rotary_axes_only_and_some_effects_come_once() {
        let gravity = r#"{"effect": "gravity", "torque": 2.0, "phase": 0.1}"#;
        let e =
            with_effects(&format!(r#"{{"effect": "offset", "force": 1}}, {gravity}"#)).unwrap_err();
        assert!(
            matches!(&e, Error::Model { path, .. } if path == "effects[1].effect"),
            "{e}"
        );
        let msg = e.to_string();
        assert!(
            msg.contains("rotary axes only") && msg.contains("offset"),
            "{msg}"
        );
        let rotary = PAPER.replace(
            r#""axis": {"mass": 25.0, "force_constant": 25.0}"#,
            r#""axis": {"kind": "rotary", "inertia": 0.5, "torque_constant": 2.0}"#,
        );
        let on = |effects: &str| {
            Model::from_json(
                &rotary.replace(r#""effects": []"#, &format!(r#""effects": [{effects}]"#)),
            )
        };
        let m = on(gravity).unwrap();
        assert_eq!(
            m.effects,
            vec![Effect::Gravity {
                torque: 2.0,
                phase: 0.1
            }]
        );
        let lf = r#"{"effect": "load_friction", "coefficient": 0.1}"#;
        let cl = r#"{"effect": "current_limit", "current": 3}"#;
        let rp = r#"{"effect": "force_ripple", "amplitude": 0.05, "pitch": 0.7}"#;
        // several ripples add up; the others come once
        assert!(on(&format!("{gravity}, {lf}, {cl}, {rp}, {rp}")).is_ok());
        for twice in [
            format!("{gravity}, {gravity}"),
            format!("{lf}, {rp}, {lf}"),
            format!("{cl}, {cl}"),
        ] {
            let e = on(&twice).unwrap_err();
            assert!(
                matches!(&e, Error::Model { path, .. } if path == "effects"),
                "{e}"
            );
            assert!(e.to_string().contains("more than one gravity"), "{e}");
        }
    }
}
