//! The checks of [`simulate`](super::simulate)'s inputs, before any step is taken.

use super::plant::TwoMass;
use super::{Drive, SimOptions};
use crate::error::{check_finite, check_len, check_time, Error, Result};
use crate::servo::model::{ControlLaw, Effect, Model};
use std::f64::consts::PI;

/// Validate the inputs of [`simulate`](super::simulate).
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
