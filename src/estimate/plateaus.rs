//! Steady-state points from a raw constant-velocity record.
//!
//! The static step needs `(v, F)` pairs at constant speed. A raw record (time,
//! position, motor force `K_F*i`, optionally the velocity reference) holds them as
//! plateaus separated by transients. A plateau is a run of constant `v_ref` (or, without
//! it, a run where the velocity differentiated from `x` over a window stays within a
//! tolerance of its running mean). Its first `settle_fraction` is dropped, and then
//! everything before the last window whose measured velocity is off the plateau value
//! by more than `velocity_tolerance`; what is left is averaged. Low-speed plateaus of a
//! stiff-friction axis often never settle within the run (the axis creeps in the
//! presliding regime while the integrator winds up); they are reported and skipped,
//! never averaged.

use crate::error::{check_finite, check_len, check_time, Error, Result};

/// Options of [`plateaus_from_recording`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlateauOptions {
    /// Leading fraction of each plateau always dropped (transient), 0.3 by default.
    pub settle_fraction: f64,
    /// Relative tolerance on the windowed velocity, 0.02 by default.
    pub velocity_tolerance: f64,
    /// Velocity window in samples (0: a tenth of the plateau, at least 5).
    pub window: usize,
    /// Fewest settled samples that make a plateau usable (20 by default).
    pub min_samples: usize,
    /// Points per plateau: the settled part is cut into this many equal chunks (1 by
    /// default); more than one gives replicate points and so a noise estimate.
    pub chunks: usize,
}

impl Default for PlateauOptions {
    fn default() -> Self {
        Self {
            settle_fraction: 0.3,
            velocity_tolerance: 0.02,
            window: 0,
            min_samples: 20,
            chunks: 1,
        }
    }
}

/// Result of [`plateaus_from_recording`].
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Plateaus {
    /// Mean measured velocity of each point [m/s] (input to [`super::fit_static`]).
    pub v: Vec<f64>,
    /// Mean force of each point [N].
    pub f: Vec<f64>,
    /// Standard deviation of the force samples behind each point [N].
    pub f_std: Vec<f64>,
    /// Samples behind each point.
    pub n_samples: Vec<usize>,
    /// Plateau (index into the `segment_*` vectors) of each point.
    pub plateau: Vec<usize>,
    /// First sample of every detected plateau.
    pub segment_start: Vec<usize>,
    /// One past the last sample of every detected plateau.
    pub segment_end: Vec<usize>,
    /// Nominal velocity of every plateau (`v_ref`, or the mean differentiated velocity).
    pub segment_velocity: Vec<f64>,
    /// First sample used of every plateau (`segment_end` when unused).
    pub segment_first_used: Vec<usize>,
    /// True for the plateaus that settled and were used.
    pub segment_settled: Vec<bool>,
    /// True for every sample that went into a point.
    pub used: Vec<bool>,
    /// What was skipped and why.
    pub notes: Vec<String>,
}

fn segments_from_ref(vr: &[f64]) -> Vec<(usize, usize, f64)> {
    let vmax = vr.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let tol = 1e-9 * vmax;
    let mut out = Vec::new();
    let mut s = 0;
    for k in 1..=vr.len() {
        if k == vr.len() || (vr[k] - vr[s]).abs() > tol {
            if vr[s].abs() > tol {
                out.push((s, k, vr[s]));
            }
            s = k;
        }
    }
    out
}

fn segments_from_x(t: &[f64], x: &[f64], half: usize, tol: f64) -> Vec<(usize, usize, f64)> {
    let n = t.len();
    if n < 2 * half + 2 {
        return Vec::new();
    }
    let vf: Vec<f64> = (half..n - half)
        .map(|k| (x[k + half] - x[k - half]) / (t[k + half] - t[k - half]))
        .collect();
    let vmax = vf.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let abs_tol = 1e-3 * vmax;
    let mut out = Vec::new();
    let mut s = 0;
    let mut sum = vf[0];
    for k in 1..=vf.len() {
        let mean = sum / (k - s) as f64;
        if k == vf.len() || (vf[k] - mean).abs() > tol * mean.abs() + abs_tol {
            if mean.abs() > abs_tol {
                out.push((s + half, k + half, mean));
            }
            if k < vf.len() {
                s = k;
                sum = vf[k];
            }
        } else {
            sum += vf[k];
        }
    }
    out
}

/// Find the constant-velocity plateaus of a record and average each settled one.
///
/// `t` time [s], `x` position [m], `force` motor force [N] (`K_F*i`), `v_ref` the
/// velocity reference when recorded. Errors when no plateau settles.
///
/// ```
/// use lugre::estimate::{plateaus_from_recording, PlateauOptions};
/// let t: Vec<f64> = (0..2000).map(|k| k as f64 * 1e-3).collect();
/// let vr: Vec<f64> = t.iter().map(|&s| if s < 1.0 { 0.1 } else { -0.1 }).collect();
/// let x: Vec<f64> = t.iter().map(|&s| if s < 1.0 { 0.1 * s } else { 0.2 - 0.1 * s }).collect();
/// let f: Vec<f64> = vr.iter().map(|v| 50.0 * v.signum()).collect();
/// let p = plateaus_from_recording(&t, &x, &f, Some(&vr), &PlateauOptions::default()).unwrap();
/// assert_eq!(p.v.len(), 2);
/// assert!((p.v[1] + 0.1).abs() < 1e-9 && (p.f[1] + 50.0).abs() < 1e-12);
/// ```
pub fn plateaus_from_recording(
    t: &[f64],
    x: &[f64],
    force: &[f64],
    v_ref: Option<&[f64]>,
    opts: &PlateauOptions,
) -> Result<Plateaus> {
    check_time("t", t)?;
    check_len("x", x, t.len(), "t")?;
    check_len("force", force, t.len(), "t")?;
    check_finite("x", x)?;
    check_finite("force", force)?;
    if let Some(vr) = v_ref {
        check_len("v_ref", vr, t.len(), "t")?;
        check_finite("v_ref", vr)?;
    }
    if !(0.0..1.0).contains(&opts.settle_fraction) {
        return Err(Error::parameter(
            "settle_fraction",
            opts.settle_fraction,
            "must be in [0, 1)",
        ));
    }
    if !(opts.velocity_tolerance > 0.0 && opts.velocity_tolerance.is_finite()) {
        return Err(Error::parameter(
            "velocity_tolerance",
            opts.velocity_tolerance,
            "must be a finite number greater than zero",
        ));
    }
    let chunks = opts.chunks.max(1);
    let segs = match v_ref {
        Some(vr) => segments_from_ref(vr),
        None => {
            let half = if opts.window > 0 {
                opts.window.div_ceil(2)
            } else {
                (t.len() / 200).max(3)
            };
            segments_from_x(t, x, half, opts.velocity_tolerance)
        }
    };
    let mut out = Plateaus {
        used: vec![false; t.len()],
        ..Default::default()
    };
    for (si, &(s, e, vnom)) in segs.iter().enumerate() {
        let len = e - s;
        out.segment_start.push(s);
        out.segment_end.push(e);
        out.segment_velocity.push(vnom);
        let w = if opts.window > 0 {
            opts.window
        } else {
            (len / 10).max(5)
        };
        let start0 = s + (opts.settle_fraction * len as f64).ceil() as usize;
        let mut first = e;
        if w < len && start0 < e {
            // the last window (start index) whose velocity is off the plateau value
            let tol = opts.velocity_tolerance * vnom.abs();
            let mut last_bad: Option<usize> = None;
            for k in (s..e - w).rev() {
                let vw = (x[k + w] - x[k]) / (t[k + w] - t[k]);
                if (vw - vnom).abs() > tol {
                    last_bad = Some(k);
                    break;
                }
            }
            first = match last_bad {
                None => start0,
                Some(k) => start0.max(k + w),
            };
        }
        let long_enough = e > first && e - first >= opts.min_samples.max(2 * chunks);
        // a steady plateau has no trend: the mean speeds of the two halves of the used
        // part agree within half the tolerance (a ramp cut into pieces does not)
        let drifting = long_enough && {
            let mid = first + (e - first) / 2;
            let v1 = (x[mid] - x[first]) / (t[mid] - t[first]);
            let v2 = (x[e - 1] - x[mid]) / (t[e - 1] - t[mid]);
            (v2 - v1).abs() > 0.5 * opts.velocity_tolerance * vnom.abs()
        };
        let settled = long_enough && !drifting;
        out.segment_settled.push(settled);
        out.segment_first_used.push(if settled { first } else { e });
        if !settled {
            out.notes.push(if drifting {
                format!(
                    "plateau {si} (v = {vnom:.4e} m/s, samples {s}..{e}) skipped: the speed drifts through it (the axis is still accelerating)"
                )
            } else {
                format!(
                    "plateau {si} (v = {vnom:.4e} m/s, samples {s}..{e}) skipped: the velocity did not settle within {:.0} % of its nominal value",
                    opts.velocity_tolerance * 100.0
                )
            });
            continue;
        }
        let m = e - first;
        for c in 0..chunks {
            let a = first + c * m / chunks;
            let b = first + (c + 1) * m / chunks;
            let n = b - a;
            let v = (x[b - 1] - x[a]) / (t[b - 1] - t[a]);
            let mean = force[a..b].iter().sum::<f64>() / n as f64;
            let var =
                force[a..b].iter().map(|f| (f - mean).powi(2)).sum::<f64>() / (n.max(2) - 1) as f64;
            out.v.push(v);
            out.f.push(mean);
            out.f_std.push(var.sqrt());
            out.n_samples.push(n);
            out.plateau.push(si);
        }
        for u in &mut out.used[first..e] {
            *u = true;
        }
    }
    if out.v.is_empty() {
        return Err(Error::Data(format!(
            "no settled constant-velocity plateau found ({} candidate segments): record longer plateaus, or give v_ref, or raise velocity_tolerance",
            segs.len()
        )));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn without_reference_and_errors() {
        let t: Vec<f64> = (0..3000).map(|k| k as f64 * 1e-3).collect();
        let x: Vec<f64> = t
            .iter()
            .map(|&s| {
                if s < 1.5 {
                    0.05 * s
                } else {
                    0.075 - 0.02 * (s - 1.5)
                }
            })
            .collect();
        let f: Vec<f64> = t
            .iter()
            .map(|&s| if s < 1.5 { 40.0 } else { -35.0 })
            .collect();
        let p = plateaus_from_recording(&t, &x, &f, None, &PlateauOptions::default()).unwrap();
        assert_eq!(p.v.len(), 2, "{p:?}");
        assert!((p.v[0] - 0.05).abs() < 1e-9 && (p.v[1] + 0.02).abs() < 1e-9);
        assert_eq!(p.f, vec![40.0, -35.0]);
        // a constant acceleration is no plateau, however it is cut
        let ramp: Vec<f64> = t.iter().map(|&s| 0.05 * s * s).collect();
        let e =
            plateaus_from_recording(&t, &ramp, &f, None, &PlateauOptions::default()).unwrap_err();
        assert!(matches!(e, Error::Data(_)), "{e}");
        let zero = vec![0.0; t.len()];
        let e = plateaus_from_recording(&t, &zero, &f, Some(&zero), &PlateauOptions::default())
            .unwrap_err();
        assert!(matches!(e, Error::Data(_)));
        let e = plateaus_from_recording(&t, &x[..10], &f, None, &PlateauOptions::default())
            .unwrap_err();
        assert!(matches!(e, Error::Input { .. }));
    }
}
