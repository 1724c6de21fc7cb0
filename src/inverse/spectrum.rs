//! Sums of a signal against sinusoids of position over a uniform grid of spatial
//! frequencies: the periodogram of a residual over position (cogging pitch search,
//! localisation of the diagnosis).
//!
//! For `k_j = k0 + j*dk` (`j < n`) and samples `(x_i, r_i)`, with `p_ij = 2*pi*k_j*x_i`:
//! `S_j = sum sin(p_ij)*r_i`, `C_j = sum cos(p_ij)*r_i` and, when asked, `SS_j`, `CC_j`,
//! `SC_j`, the sums of `sin^2`, `cos^2` and `sin*cos` (the normal equations of the
//! best sinusoid at `k_j`).
//!
//! The angles advance over `j` by the rotation through `2*pi*dk*x_i`, started from an
//! exact `sin_cos` of `2*pi*(k_j*x_i)` every [`RESEED`] frequencies, so the error of
//! the recurrence stays below about `RESEED` rounding steps (1e-14 of the terms); the
//! sums run over blocks of samples with four partial sums each. The NumPy twin
//! `lugre.reference.position_sums` evaluates `sin` and `cos` of the outer product
//! directly; the two agree to about 1e-13 of the sums' scale.

use crate::error::{check_finite, check_len, Error, Result};

/// Frequencies advanced by rotation between two exact evaluations.
pub const RESEED: usize = 32;

/// Most frequencies in one call.
pub const MAX_FREQUENCIES: usize = 1 << 26;

/// Samples per block (their angles, rotations and values stay in the L1 cache).
const BLOCK: usize = 256;

/// The sums of [`position_sums`], one element per frequency.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PositionSums {
    /// `sum sin(2*pi*k_j*x_i)*r_i`.
    pub s: Vec<f64>,
    /// `sum cos(2*pi*k_j*x_i)*r_i`.
    pub c: Vec<f64>,
    /// `sum sin^2` (empty unless `squares`).
    pub ss: Vec<f64>,
    /// `sum cos^2` (empty unless `squares`).
    pub cc: Vec<f64>,
    /// `sum sin*cos` (empty unless `squares`).
    pub sc: Vec<f64>,
}

/// The sums of `r` against `sin` and `cos` of `2*pi*k_j*x` for `k_j = k0 + j*dk`,
/// `j < n` (see the module documentation); `squares` adds the sums of `sin^2`,
/// `cos^2` and `sin*cos`.
///
/// Errors ([`Error::Input`] or [`Error::Parameter`] naming the argument): `x` or `r`
/// not finite, `r` of another length than `x`, `k0` not finite, `dk` not finite or
/// `<= 0`, `n` zero or above [`MAX_FREQUENCIES`].
///
/// ```
/// use lugre::inverse::position_sums;
/// let x: Vec<f64> = (0..100).map(|i| i as f64 * 1e-3).collect();
/// let r: Vec<f64> = x.iter().map(|x| (2.0 * std::f64::consts::PI * 50.0 * x).sin()).collect();
/// let p = position_sums(&x, &r, 10.0, 10.0, 8, false).unwrap();
/// // the sinusoid of 50 periods per metre (j = 4) stands out
/// let best = (0..8).max_by(|&a, &b| p.s[a].abs().total_cmp(&p.s[b].abs())).unwrap();
/// assert_eq!(best, 4);
/// ```
pub fn position_sums(
    x: &[f64],
    r: &[f64],
    k0: f64,
    dk: f64,
    n: usize,
    squares: bool,
) -> Result<PositionSums> {
    check_finite("x", x)?;
    check_len("r", r, x.len(), "x")?;
    check_finite("r", r)?;
    if !k0.is_finite() {
        return Err(Error::parameter(
            "k0",
            k0,
            "must be a finite spatial frequency [1/m]",
        ));
    }
    if !(dk.is_finite() && dk > 0.0) {
        return Err(Error::parameter(
            "dk",
            dk,
            "must be a finite frequency step greater than zero [1/m]",
        ));
    }
    if n == 0 || n > MAX_FREQUENCIES {
        return Err(Error::parameter(
            "n",
            n as f64,
            format!("must be between 1 and {MAX_FREQUENCIES} frequencies"),
        ));
    }
    let mut out = PositionSums {
        s: vec![0.0; n],
        c: vec![0.0; n],
        ..Default::default()
    };
    if squares {
        out.ss = vec![0.0; n];
        out.cc = vec![0.0; n];
        out.sc = vec![0.0; n];
    }
    let mut blk = Block::default();
    for (xb, rb) in x.chunks(BLOCK).zip(r.chunks(BLOCK)) {
        blk.load(xb, rb, dk);
        if squares {
            blk.sums::<true>(xb, k0, dk, &mut out);
        } else {
            blk.sums::<false>(xb, k0, dk, &mut out);
        }
    }
    Ok(out)
}

/// One block of samples, padded to a multiple of 4 with zeros (which add nothing).
struct Block {
    len: usize,
    r: [f64; BLOCK],
    cd: [f64; BLOCK],
    sd: [f64; BLOCK],
    c: [f64; BLOCK],
    s: [f64; BLOCK],
}

impl Default for Block {
    fn default() -> Self {
        Block {
            len: 0,
            r: [0.0; BLOCK],
            cd: [0.0; BLOCK],
            sd: [0.0; BLOCK],
            c: [0.0; BLOCK],
            s: [0.0; BLOCK],
        }
    }
}

const TAU: f64 = 2.0 * core::f64::consts::PI;

impl Block {
    /// The samples' values and rotations through `2*pi*dk*x_i`.
    fn load(&mut self, x: &[f64], r: &[f64], dk: f64) {
        let m = x.len();
        self.len = m.div_ceil(4) * 4;
        for i in 0..self.len {
            if i < m {
                let (sd, cd) = (TAU * (dk * x[i])).sin_cos();
                (self.r[i], self.cd[i], self.sd[i]) = (r[i], cd, sd);
            } else {
                (self.r[i], self.cd[i], self.sd[i]) = (0.0, 0.0, 0.0);
            }
        }
    }

    /// Four partial sums of each product over the block, the angles first rotated
    /// when `ROT`.
    #[inline(always)]
    fn accumulate<const ROT: bool, const SQUARES: bool>(&mut self) -> [[f64; 4]; 5] {
        let len = self.len;
        let mut acc = [[0.0f64; 4]; 5];
        let lanes = self.c[..len]
            .chunks_exact_mut(4)
            .zip(self.s[..len].chunks_exact_mut(4))
            .zip(self.cd[..len].chunks_exact(4))
            .zip(self.sd[..len].chunks_exact(4))
            .zip(self.r[..len].chunks_exact(4));
        for ((((c, s), cd), sd), r) in lanes {
            for l in 0..4 {
                let (mut cl, mut sl) = (c[l], s[l]);
                if ROT {
                    (cl, sl) = (cl * cd[l] - sl * sd[l], sl * cd[l] + cl * sd[l]);
                    (c[l], s[l]) = (cl, sl);
                }
                acc[0][l] += sl * r[l];
                acc[1][l] += cl * r[l];
                if SQUARES {
                    acc[2][l] += sl * sl;
                    acc[3][l] += cl * cl;
                    acc[4][l] += sl * cl;
                }
            }
        }
        acc
    }

    /// Add the block's sums to `out`.
    fn sums<const SQUARES: bool>(&mut self, x: &[f64], k0: f64, dk: f64, out: &mut PositionSums) {
        let n = out.s.len();
        let len = self.len;
        let mut j0 = 0;
        while j0 < n {
            // exact angles at k_j0 (the padding stays at zero)
            let k = k0 + j0 as f64 * dk;
            for (i, &xi) in x.iter().enumerate() {
                (self.s[i], self.c[i]) = (TAU * (k * xi)).sin_cos();
            }
            for i in x.len()..len {
                (self.s[i], self.c[i]) = (0.0, 0.0);
            }
            for j in j0..(j0 + RESEED).min(n) {
                let acc = if j > j0 {
                    self.accumulate::<true, SQUARES>()
                } else {
                    self.accumulate::<false, SQUARES>()
                };
                let total = |a: &[f64; 4]| (a[0] + a[1]) + (a[2] + a[3]);
                out.s[j] += total(&acc[0]);
                out.c[j] += total(&acc[1]);
                if SQUARES {
                    out.ss[j] += total(&acc[2]);
                    out.cc[j] += total(&acc[3]);
                    out.sc[j] += total(&acc[4]);
                }
            }
            j0 += RESEED;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn direct(x: &[f64], r: &[f64], k0: f64, dk: f64, n: usize) -> [Vec<f64>; 5] {
        let mut o: [Vec<f64>; 5] = Default::default();
        for j in 0..n {
            let k = k0 + j as f64 * dk;
            let mut a = [0.0; 5];
            for (&xi, &ri) in x.iter().zip(r) {
                let (s, c) = (TAU * (k * xi)).sin_cos();
                a[0] += s * ri;
                a[1] += c * ri;
                a[2] += s * s;
                a[3] += c * c;
                a[4] += s * c;
            }
            for q in 0..5 {
                o[q].push(a[q]);
            }
        }
        o
    }

    #[test]
    fn as_the_direct_sums() {
        let m = 1003; // not a multiple of the block or of 4
        let x: Vec<f64> = (0..m)
            .map(|i| 0.2 * (i as f64 * 0.37).sin() + 1e-4 * i as f64)
            .collect();
        let r: Vec<f64> = (0..m).map(|i| ((i * 7919) % 101) as f64 - 50.0).collect();
        for (k0, dk, n) in [(3.0, 1.25, 150), (-40.0, 0.5, 1), (900.0, 2.5, 97)] {
            let p = position_sums(&x, &r, k0, dk, n, true).unwrap();
            let want = direct(&x, &r, k0, dk, n);
            let got = [&p.s, &p.c, &p.ss, &p.cc, &p.sc];
            for q in 0..5 {
                let scale = want[q].iter().fold(1.0f64, |a, b| a.max(b.abs()));
                for j in 0..n {
                    let e = (got[q][j] - want[q][j]).abs() / scale;
                    assert!(e < 1e-12, "sum {q} at {j}: {} vs {}", got[q][j], want[q][j]);
                }
            }
            let plain = position_sums(&x, &r, k0, dk, n, false).unwrap();
            assert_eq!((plain.s, plain.c), (p.s, p.c));
            assert!(plain.ss.is_empty());
        }
    }

    #[test]
    fn bad_inputs_name_the_argument() {
        let name = |e: Error| match e {
            Error::Input { name, .. } | Error::Parameter { name, .. } => name,
            other => panic!("{other}"),
        };
        let x = [0.0, 1.0];
        let e = |x: &[f64], r: &[f64], k0, dk, n| {
            name(position_sums(x, r, k0, dk, n, true).unwrap_err())
        };
        assert_eq!(e(&[f64::NAN, 1.0], &x, 1.0, 1.0, 3), "x");
        assert_eq!(e(&x, &[0.0], 1.0, 1.0, 3), "r");
        assert_eq!(e(&x, &[0.0, f64::INFINITY], 1.0, 1.0, 3), "r");
        assert_eq!(e(&x, &x, f64::NAN, 1.0, 3), "k0");
        assert_eq!(e(&x, &x, 1.0, 0.0, 3), "dk");
        assert_eq!(e(&x, &x, 1.0, -1.0, 3), "dk");
        assert_eq!(e(&x, &x, 1.0, f64::INFINITY, 3), "dk");
        assert_eq!(e(&x, &x, 1.0, 1.0, 0), "n");
        assert_eq!(e(&x, &x, 1.0, 1.0, MAX_FREQUENCIES + 1), "n");
        let p = position_sums(&[], &[], 1.0, 1.0, 2, true).unwrap();
        assert_eq!(p.s, [0.0, 0.0]);
    }
}
