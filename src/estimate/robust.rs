//! Robust weight functions and scale for iteratively reweighted least squares (IRLS).
//!
//! The seed paper (eqs. 19-24) solves a sequence of weighted problems with equivalent
//! weights `p_i*w_i`, the weight factor `w_i` following the IGG scheme of Zhou Jiangwen
//! ("Institute of Geodesy and Geophysics"): full weight for small residuals, a
//! descending weight in a transition band, zero weight (rejection) for gross errors.
//! Residuals are measured in units of a robust scale, `1.4826*MAD`, which equals the
//! standard deviation for Gaussian noise and is not inflated by a minority of outliers.
//! Huber's and Tukey's biweight functions (tuning constants for 95 % Gaussian
//! efficiency) and plain least squares are there for comparison.

use crate::error::{Error, Result};

/// Robust weight function applied to standardised residuals `u = e/s`.
///
/// ```
/// use lugre::estimate::Weighting;
/// let w = Weighting::default(); // IGG with k0 = 1.5, k1 = 2.5
/// assert_eq!(w.weight(1.0), 1.0);
/// assert!((w.weight(2.0) - 0.75).abs() < 1e-12);
/// assert_eq!(w.weight(3.0), 0.0);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Weighting {
    /// IGG: `w = 1` for `|u| <= k0`, `k0/|u|` for `k0 < |u| <= k1`, `0` beyond.
    Igg {
        /// Start of the down-weighting band (1.5 by default).
        k0: f64,
        /// Rejection threshold (2.5 by default).
        k1: f64,
    },
    /// Huber: `w = 1` for `|u| <= c`, `c/|u|` beyond (never rejects).
    Huber {
        /// Tuning constant (1.345 by default).
        c: f64,
    },
    /// Tukey biweight: `w = (1 - (u/c)^2)^2` for `|u| < c`, `0` beyond.
    Tukey {
        /// Tuning constant (4.685 by default).
        c: f64,
    },
    /// Plain least squares: every weight 1.
    None,
}

impl Default for Weighting {
    fn default() -> Self {
        Weighting::igg()
    }
}

impl Weighting {
    /// IGG with the paper's constants `k0 = 1.5`, `k1 = 2.5`.
    pub fn igg() -> Self {
        Weighting::Igg { k0: 1.5, k1: 2.5 }
    }

    /// Huber with `c = 1.345`.
    pub fn huber() -> Self {
        Weighting::Huber { c: 1.345 }
    }

    /// Tukey biweight with `c = 4.685`.
    pub fn tukey() -> Self {
        Weighting::Tukey { c: 4.685 }
    }

    /// The scheme named `igg`, `huber`, `tukey` or `none` (also `ls`), with its
    /// default constants (case-insensitive).
    ///
    /// ```
    /// use lugre::estimate::Weighting;
    /// assert_eq!(Weighting::from_name("Huber").unwrap(), Weighting::huber());
    /// assert!(Weighting::from_name("cauchy").is_err());
    /// ```
    pub fn from_name(name: &str) -> Result<Self> {
        match name.to_ascii_lowercase().as_str() {
            "igg" => Ok(Weighting::igg()),
            "huber" => Ok(Weighting::huber()),
            "tukey" | "biweight" => Ok(Weighting::tukey()),
            "none" | "ls" | "least_squares" => Ok(Weighting::None),
            other => Err(Error::input(
                "weighting",
                format!(
                    "unknown weighting \"{other}\": use \"igg\", \"huber\", \"tukey\" or \"none\""
                ),
            )),
        }
    }

    /// Short lower-case name (`igg`, `huber`, `tukey`, `none`).
    pub fn name(&self) -> &'static str {
        match self {
            Weighting::Igg { .. } => "igg",
            Weighting::Huber { .. } => "huber",
            Weighting::Tukey { .. } => "tukey",
            Weighting::None => "none",
        }
    }

    /// Check the tuning constants (finite, positive, `k1 >= k0`).
    pub fn validate(&self) -> Result<()> {
        let bad = |name: &str, v: f64| {
            Err(Error::parameter(
                name,
                v,
                "must be a finite number greater than zero",
            ))
        };
        match *self {
            Weighting::Igg { k0, k1 } => {
                if !(k0.is_finite() && k0 > 0.0) {
                    return bad("weighting.k0", k0);
                }
                if !(k1.is_finite() && k1 >= k0) {
                    return Err(Error::parameter(
                        "weighting.k1",
                        k1,
                        "must be finite and at least k0",
                    ));
                }
            }
            Weighting::Huber { c } | Weighting::Tukey { c } => {
                if !(c.is_finite() && c > 0.0) {
                    return bad("weighting.c", c);
                }
            }
            Weighting::None => {}
        }
        Ok(())
    }

    /// Weight of a standardised residual `u = e/s`.
    #[inline]
    pub fn weight(&self, u: f64) -> f64 {
        let a = u.abs();
        if a.is_nan() {
            return 0.0;
        }
        match *self {
            Weighting::Igg { k0, k1 } => {
                if a <= k0 {
                    1.0
                } else if a <= k1 {
                    k0 / a
                } else {
                    0.0
                }
            }
            Weighting::Huber { c } => {
                if a <= c {
                    1.0
                } else {
                    c / a
                }
            }
            Weighting::Tukey { c } => {
                if a < c {
                    let r = a / c;
                    let q = 1.0 - r * r;
                    q * q
                } else {
                    0.0
                }
            }
            Weighting::None => 1.0,
        }
    }

    /// Weights of residuals `e` at scale `s`; with `s == 0` (a perfect fit) every
    /// residual that is exactly zero gets weight 1 and the others the weight at
    /// infinity.
    pub fn weights(&self, e: &[f64], s: f64) -> Vec<f64> {
        e.iter()
            .map(|&ei| {
                if s > 0.0 {
                    self.weight(ei / s)
                } else if ei == 0.0 {
                    1.0
                } else {
                    self.weight(f64::INFINITY)
                }
            })
            .collect()
    }
}

/// Median of `a` (NaN for an empty slice); NaNs are ignored.
///
/// The middle order statistic, or half the sum of the two middle ones, found by
/// selection in linear time (the same values a sort gives).
pub fn median(a: &[f64]) -> f64 {
    let mut b: Vec<f64> = a.iter().copied().filter(|x| !x.is_nan()).collect();
    if b.is_empty() {
        return f64::NAN;
    }
    let n = b.len();
    let (left, mid, _) = b.select_nth_unstable_by(n / 2, |x, y| x.total_cmp(y));
    let hi = *mid;
    if n % 2 == 1 {
        hi
    } else {
        // the largest of the lower half is the order statistic n/2 - 1
        let lo = left.iter().copied().fold(f64::NEG_INFINITY, |m, x| {
            if x.total_cmp(&m).is_gt() {
                x
            } else {
                m
            }
        });
        0.5 * (lo + hi)
    }
}

/// Empirical quantile `q` in [0, 1] of `a` (linear interpolation, NaN when empty).
pub fn quantile(a: &[f64], q: f64) -> f64 {
    let mut b: Vec<f64> = a.iter().copied().filter(|x| !x.is_nan()).collect();
    if b.is_empty() {
        return f64::NAN;
    }
    b.sort_by(|x, y| x.total_cmp(y));
    let pos = q.clamp(0.0, 1.0) * (b.len() - 1) as f64;
    let lo = pos.floor() as usize;
    let hi = pos.ceil() as usize;
    b[lo] + (b[hi] - b[lo]) * (pos - lo as f64)
}

/// Robust scale of residuals: `1.4826*MAD` (median absolute deviation from the median).
///
/// When more than half of the residuals are equal, the MAD is zero; the scale then
/// falls back to `1.2533*mean|e - median|` (the Gaussian-consistent mean absolute
/// deviation), and to 0 only when every residual is equal.
///
/// ```
/// use lugre::estimate::robust_scale;
/// let e = [-1.0, 0.0, 1.0, 0.0, 100.0];
/// assert!((robust_scale(&e) - 1.4826).abs() < 1e-12);
/// ```
pub fn robust_scale(e: &[f64]) -> f64 {
    let m = median(e);
    if !m.is_finite() {
        return 0.0;
    }
    let dev: Vec<f64> = e
        .iter()
        .filter(|x| !x.is_nan())
        .map(|x| (x - m).abs())
        .collect();
    let mad = median(&dev);
    if mad > 0.0 && mad.is_finite() {
        return 1.4826 * mad;
    }
    let finite: Vec<f64> = dev.into_iter().filter(|d| d.is_finite()).collect();
    if finite.is_empty() {
        return 0.0;
    }
    1.2533 * finite.iter().sum::<f64>() / finite.len() as f64
}

/// Two-sided 95 % quantile of Student's t with `dof` degrees of freedom (Cornish-Fisher
/// expansion about the normal quantile; exact to about 1e-3 for `dof >= 3`, NaN for
/// `dof < 1`).
pub fn t_quantile_975(dof: f64) -> f64 {
    if dof.is_nan() || dof < 1.0 {
        return f64::NAN;
    }
    if dof == 1.0 {
        return 12.706;
    }
    if dof == 2.0 {
        return 4.303;
    }
    let z: f64 = 1.959_963_984_540_054;
    let n = dof;
    let z3 = z * z * z;
    let z5 = z3 * z * z;
    let z7 = z5 * z * z;
    z + (z3 + z) / (4.0 * n)
        + (5.0 * z5 + 16.0 * z3 + 3.0 * z) / (96.0 * n * n)
        + (3.0 * z7 + 19.0 * z5 + 17.0 * z3 - 15.0 * z) / (384.0 * n * n * n)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn igg_weights() {
        let w = Weighting::igg();
        assert_eq!(w.weight(-1.5), 1.0);
        assert!((w.weight(2.5) - 0.6).abs() < 1e-12);
        assert_eq!(w.weight(2.5000001), 0.0);
        assert_eq!(w.weight(f64::NAN), 0.0);
        assert_eq!(Weighting::None.weight(1e300), 1.0);
    }

    #[test]
    fn huber_tukey() {
        assert!((Weighting::huber().weight(2.69) - 0.5).abs() < 1e-12);
        assert_eq!(Weighting::tukey().weight(4.685), 0.0);
        assert!((Weighting::tukey().weight(0.0) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn median_by_selection_equals_median_by_sorting() {
        let mut s: u64 = 7;
        for n in 1..200usize {
            let a: Vec<f64> = (0..n)
                .map(|k| {
                    s = s.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
                    // ties and signed zeros among random values
                    match k % 7 {
                        0 => 0.0,
                        1 => -0.0,
                        2 => 1.5,
                        _ => (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5,
                    }
                })
                .collect();
            let mut b = a.clone();
            b.sort_by(|x, y| x.total_cmp(y));
            let want = if n % 2 == 1 {
                b[n / 2]
            } else {
                0.5 * (b[n / 2 - 1] + b[n / 2])
            };
            assert_eq!(median(&a).to_bits(), want.to_bits(), "n = {n}");
        }
        assert!(median(&[f64::NAN]).is_nan());
        assert_eq!(median(&[3.0, f64::NAN, 1.0]), 2.0);
    }

    #[test]
    fn scale_guards() {
        assert_eq!(robust_scale(&[]), 0.0);
        assert_eq!(robust_scale(&[2.0, 2.0, 2.0]), 0.0);
        let s = robust_scale(&[0.0, 0.0, 0.0, 1.0]);
        assert!(s > 0.0);
        let w = Weighting::igg().weights(&[0.0, 1.0], 0.0);
        assert_eq!(w, vec![1.0, 0.0]);
    }

    #[test]
    fn t_quantiles() {
        assert!((t_quantile_975(10.0) - 2.228).abs() < 2e-3);
        assert!((t_quantile_975(5.0) - 2.571).abs() < 1e-2);
        assert!((t_quantile_975(1e6) - 1.96).abs() < 1e-3);
        assert!(t_quantile_975(0.0).is_nan());
    }

    #[test]
    fn validate_constants() {
        assert!(Weighting::Igg { k0: 2.0, k1: 1.0 }.validate().is_err());
        assert!(Weighting::Huber { c: 0.0 }.validate().is_err());
        assert!(Weighting::igg().validate().is_ok());
    }
}
