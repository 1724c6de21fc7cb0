//! Zero-phase low-pass by second-order sections run forward and backward.
//!
//! [`Lowpass::filtfilt`] follows SciPy's `sosfiltfilt(sos, y, padtype="odd",
//! padlen=padlen)` step for step: odd extension of `padlen` samples at both ends, each
//! section started in the steady state of the first (then last) extended sample
//! (`sosfilt_zi`), the sections run in direct form II transposed, forward then backward,
//! and the extension cut off; the one difference: states under [`FLUSH`] are set to
//! zero every [`FLUSH_EVERY`] samples. The coefficients come from the caller (a
//! Butterworth design, `scipy.signal.butter(..., output="sos")` in the Python package).

use crate::error::{Error, Result};

/// Signals filtered side by side by [`Lowpass::filtfilt_many`].
pub const LANES: usize = 4;

/// Samples of a pass between two flushes of the sections' states.
pub const FLUSH_EVERY: usize = 32;

/// States smaller than this in magnitude are set to zero after every [`FLUSH_EVERY`]
/// samples of a pass: a signal that falls to zero leaves states decaying through the
/// subnormal numbers (or cycling among the smallest of them), where each operation
/// takes a hundred times longer (a `position_friction` hat column, zero over most
/// of the record, filtered 40 times slower than the motor force).
pub const FLUSH: f64 = 1e-270;

/// Set the states under [`FLUSH`] in magnitude to zero.
#[inline(always)]
fn flush<const W: usize>(states: &mut [[f64; W]]) {
    for v in states.iter_mut().flatten() {
        if v.abs() < FLUSH {
            *v = 0.0;
        }
    }
}

/// One sample through `N` sections (transposed direct form II).
#[inline(always)]
fn step_n<const N: usize>(c: &[[f64; 6]; N], st: &mut [[f64; 2]; N], mut x: f64) -> f64 {
    for j in 0..N {
        let out = c[j][0] * x + st[j][0];
        st[j][0] = c[j][1] * x - c[j][4] * out + st[j][1];
        st[j][1] = c[j][2] * x - c[j][5] * out;
        x = out;
    }
    x
}

/// A cascade of second-order sections `[b0, b1, b2, 1, a1, a2]` run forward and
/// backward; no sections is the identity.
#[derive(Debug, Clone, PartialEq)]
pub struct Lowpass {
    sections: Vec<[f64; 6]>,
    zi: Vec<[f64; 2]>,
    padlen: usize,
}

impl Lowpass {
    /// The identity (no filtering).
    pub fn identity() -> Lowpass {
        Lowpass {
            sections: Vec::new(),
            zi: Vec::new(),
            padlen: 0,
        }
    }

    /// A filter from its sections (`a0` must be 1) and the odd-extension length
    /// (capped at `len - 1` of each signal, as SciPy does).
    pub fn new(sections: Vec<[f64; 6]>, padlen: usize) -> Result<Lowpass> {
        let mut zi = Vec::with_capacity(sections.len());
        let mut scale = 1.0;
        for (k, s) in sections.iter().enumerate() {
            if s.iter().any(|c| !c.is_finite()) {
                return Err(Error::input(
                    "sos",
                    format!("section {k} has a non-finite coefficient"),
                ));
            }
            if s[3] != 1.0 {
                return Err(Error::input(
                    "sos",
                    format!(
                        "section {k} has a0 = {}: normalise the sections to a0 = 1",
                        s[3]
                    ),
                ));
            }
            let (b0, b1, b2, a1, a2) = (s[0], s[1], s[2], s[4], s[5]);
            let den = 1.0 + a1 + a2;
            if den == 0.0 {
                return Err(Error::input(
                    "sos",
                    format!("section {k} has a pole at z = 1: it is not a low-pass"),
                ));
            }
            // steady state of the transposed direct form II for a unit input:
            // (1 + a1) z0 - z1 = b1 - a1 b0 and a2 z0 + z1 = b2 - a2 b0
            let (c0, c1) = (b1 - a1 * b0, b2 - a2 * b0);
            let z0 = (c0 + c1) / den;
            let z1 = c1 - a2 * z0;
            zi.push([scale * z0, scale * z1]);
            scale *= (b0 + b1 + b2) / den;
        }
        Ok(Lowpass {
            sections,
            zi,
            padlen,
        })
    }

    /// Whether the filter does nothing.
    pub fn is_identity(&self) -> bool {
        self.sections.is_empty()
    }

    /// Run the sections once over `y` in place (from the end when `backward`), started at the
    /// first sample of that order times the steady state.
    fn run(&self, y: &mut [f64], backward: bool) {
        let ns = self.sections.len();
        match ns {
            1 => self.run_n::<1>(y, backward),
            2 => self.run_n::<2>(y, backward),
            3 => self.run_n::<3>(y, backward),
            4 => self.run_n::<4>(y, backward),
            _ => self.run_any(y, backward),
        }
    }

    /// [`Lowpass::run`] with `N` sections, their coefficients and states in registers.
    #[inline(always)]
    fn run_n<const N: usize>(&self, y: &mut [f64], backward: bool) {
        let mut c = [[0.0f64; 6]; N];
        c.copy_from_slice(&self.sections[..N]);
        let mut st = [[0.0f64; 2]; N];
        let x0 = if backward { y[y.len() - 1] } else { y[0] };
        for (s, z) in st.iter_mut().zip(&self.zi) {
            *s = [z[0] * x0, z[1] * x0];
        }
        if backward {
            for block in y.rchunks_mut(FLUSH_EVERY) {
                for yk in block.iter_mut().rev() {
                    *yk = step_n(&c, &mut st, *yk);
                }
                flush(&mut st);
            }
        } else {
            for block in y.chunks_mut(FLUSH_EVERY) {
                for yk in block.iter_mut() {
                    *yk = step_n(&c, &mut st, *yk);
                }
                flush(&mut st);
            }
        }
    }

    /// [`Lowpass::run`] with any number of sections.
    fn run_any(&self, y: &mut [f64], backward: bool) {
        let mut st = vec![[0.0f64; 2]; self.sections.len()];
        let x0 = if backward { y[y.len() - 1] } else { y[0] };
        for (s, z) in st.iter_mut().zip(&self.zi) {
            *s = [z[0] * x0, z[1] * x0];
        }
        let one = |yk: &mut f64, st: &mut [[f64; 2]]| {
            let mut x = *yk;
            for (c, s) in self.sections.iter().zip(st.iter_mut()) {
                let out = c[0] * x + s[0];
                s[0] = c[1] * x - c[4] * out + s[1];
                s[1] = c[2] * x - c[5] * out;
                x = out;
            }
            *yk = x;
        };
        if backward {
            for block in y.rchunks_mut(FLUSH_EVERY) {
                block.iter_mut().rev().for_each(|yk| one(yk, &mut st));
                flush(&mut st);
            }
        } else {
            for block in y.chunks_mut(FLUSH_EVERY) {
                block.iter_mut().for_each(|yk| one(yk, &mut st));
                flush(&mut st);
            }
        }
    }

    /// The zero-phase filtered signal (a copy when the filter is the identity).
    pub fn filtfilt(&self, y: &[f64]) -> Vec<f64> {
        let n = y.len();
        if self.is_identity() || n == 0 {
            return y.to_vec();
        }
        let (mut ext, edge) = self.extend(y);
        // forward, then backward from the last output (SciPy reverses the signal twice)
        self.run(&mut ext, false);
        self.run(&mut ext, true);
        cut(ext, edge, n)
    }

    /// [`Lowpass::filtfilt`] of each of `ys`, with the same numbers: up to [`LANES`]
    /// signals of one length run side by side (the recursion of one signal is a chain
    /// of dependent multiply-adds; independent signals fill the time between them).
    pub fn filtfilt_many(&self, ys: &[&[f64]]) -> Vec<Vec<f64>> {
        let ns = self.sections.len();
        if !(1..=4).contains(&ns) {
            return ys.iter().map(|y| self.filtfilt(y)).collect();
        }
        let mut out: Vec<Vec<f64>> = vec![Vec::new(); ys.len()];
        // the signals of each length, in order
        let mut groups: Vec<(usize, Vec<usize>)> = Vec::new();
        for (j, y) in ys.iter().enumerate() {
            match groups.iter_mut().find(|(n, _)| *n == y.len()) {
                Some((_, g)) => g.push(j),
                None => groups.push((y.len(), vec![j])),
            }
        }
        for (n, group) in groups {
            for chunk in group.chunks(LANES) {
                if chunk.len() == 1 {
                    out[chunk[0]] = self.filtfilt(ys[chunk[0]]);
                    continue;
                }
                let f = self.filtfilt_lanes(n, chunk.len(), |l, k| ys[chunk[l]][k]);
                for (l, &j) in chunk.iter().enumerate() {
                    out[j] = f.lane(l).collect();
                }
            }
        }
        out
    }

    /// [`Lowpass::filtfilt`] of up to [`LANES`] signals of length `n`, sample `k` of
    /// signal `l` read as `y(l, k)` (a matrix's column, where it is), side by side
    /// when there are several and the filter has 1 to 4 sections ([`Lowpass::run_n`]
    /// on every lane at once: the same numbers lane by lane), one by one otherwise.
    ///
    /// # Panics
    /// When `width` exceeds [`LANES`].
    pub fn filtfilt_lanes(&self, n: usize, width: usize, y: impl Fn(usize, usize) -> f64) -> Lanes {
        assert!(width <= LANES, "at most {LANES} signals side by side");
        let ns = self.sections.len();
        if n == 0 || width < 2 || !(1..=4).contains(&ns) {
            let one = (0..width)
                .map(|l| self.filtfilt(&(0..n).map(|k| y(l, k)).collect::<Vec<f64>>()))
                .collect();
            return Lanes {
                buf: Vec::new(),
                one,
                edge: 0,
                n,
                width,
            };
        }
        // the extensions side by side, sample by sample (zeros in unused lanes)
        let edge = self.padlen.min(n - 1);
        let mut buf = vec![[0.0f64; LANES]; n + 2 * edge];
        for l in 0..width {
            let (first, last) = (y(l, 0), y(l, n - 1));
            for k in 0..edge {
                buf[k][l] = 2.0 * first - y(l, edge - k);
                buf[edge + n + k][l] = 2.0 * last - y(l, n - 2 - k);
            }
            for (k, b) in buf[edge..edge + n].iter_mut().enumerate() {
                b[l] = y(l, k);
            }
        }
        self.run_lanes(&mut buf, false);
        self.run_lanes(&mut buf, true);
        Lanes {
            buf,
            one: Vec::new(),
            edge,
            n,
            width,
        }
    }

    /// The odd extension of `y` (not empty) by `edge = min(padlen, len - 1)` samples at
    /// both ends, and `edge`.
    fn extend(&self, y: &[f64]) -> (Vec<f64>, usize) {
        let n = y.len();
        let edge = self.padlen.min(n - 1);
        let mut ext = Vec::with_capacity(n + 2 * edge);
        let (first, last) = (y[0], y[n - 1]);
        for k in (1..=edge).rev() {
            ext.push(2.0 * first - y[k]);
        }
        ext.extend_from_slice(y);
        for k in 1..=edge {
            ext.push(2.0 * last - y[n - 1 - k]);
        }
        (ext, edge)
    }

    /// [`Lowpass::run`] of [`LANES`] signals of one length side by side, stored sample
    /// by sample (1 to 4 sections).
    fn run_lanes(&self, buf: &mut [[f64; LANES]], backward: bool) {
        match self.sections.len() {
            1 => self.lanes::<1>(buf, backward),
            2 => self.lanes::<2>(buf, backward),
            3 => self.lanes::<3>(buf, backward),
            _ => self.lanes::<4>(buf, backward),
        }
    }

    /// [`Lowpass::run_n`] of [`LANES`] signals side by side: every operation of one
    /// signal's run on all lanes at once (the same numbers lane by lane).
    #[inline(always)]
    fn lanes<const N: usize>(&self, buf: &mut [[f64; LANES]], backward: bool) {
        const L: usize = LANES;
        let mut c = [[0.0f64; 6]; N];
        c.copy_from_slice(&self.sections[..N]);
        let len = buf.len();
        let x0 = if backward { buf[len - 1] } else { buf[0] };
        let mut s0 = [[0.0f64; L]; N];
        let mut s1 = [[0.0f64; L]; N];
        for j in 0..N {
            for l in 0..L {
                s0[j][l] = self.zi[j][0] * x0[l];
                s1[j][l] = self.zi[j][1] * x0[l];
            }
        }
        if backward {
            for block in buf.rchunks_mut(FLUSH_EVERY) {
                for b in block.iter_mut().rev() {
                    *b = step_lanes(&c, &mut s0, &mut s1, *b);
                }
                flush(&mut s0);
                flush(&mut s1);
            }
        } else {
            for block in buf.chunks_mut(FLUSH_EVERY) {
                for b in block.iter_mut() {
                    *b = step_lanes(&c, &mut s0, &mut s1, *b);
                }
                flush(&mut s0);
                flush(&mut s1);
            }
        }
    }
}

/// One sample of [`LANES`] signals through `N` sections: [`step_n`] lane by lane, each
/// operation on all lanes at once.
#[inline(always)]
fn step_lanes<const N: usize>(
    c: &[[f64; 6]; N],
    s0: &mut [[f64; LANES]; N],
    s1: &mut [[f64; LANES]; N],
    mut x: [f64; LANES],
) -> [f64; LANES] {
    for j in 0..N {
        let cj = c[j];
        let mut out = [0.0f64; LANES];
        for l in 0..LANES {
            out[l] = cj[0] * x[l] + s0[j][l];
        }
        for l in 0..LANES {
            s0[j][l] = cj[1] * x[l] - cj[4] * out[l] + s1[j][l];
        }
        for l in 0..LANES {
            s1[j][l] = cj[2] * x[l] - cj[5] * out[l];
        }
        x = out;
    }
    x
}

/// The signal of `n` samples in an extension by `edge` samples at both ends.
/// Signals filtered side by side by [`Lowpass::filtfilt_lanes`], stored sample by
/// sample with their extensions.
#[derive(Debug, Clone)]
pub struct Lanes {
    /// The signals side by side, extensions included (empty when filtered one by one).
    buf: Vec<[f64; LANES]>,
    /// The signals filtered one by one.
    one: Vec<Vec<f64>>,
    edge: usize,
    n: usize,
    width: usize,
}

impl Lanes {
    /// Number of signals.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Sample `k` of the filtered signal `l` (`l < width`, `k < n`).
    #[inline]
    pub fn get(&self, l: usize, k: usize) -> f64 {
        assert!(l < self.width, "lane {l} of {}", self.width);
        if self.buf.is_empty() {
            self.one[l][k]
        } else {
            self.buf[self.edge + k][l]
        }
    }

    /// The filtered signal `l` (`l < width`), sample by sample.
    pub fn lane(&self, l: usize) -> impl Iterator<Item = f64> + '_ {
        (0..self.n).map(move |k| self.get(l, k))
    }
}

fn cut(mut ext: Vec<f64>, edge: usize, n: usize) -> Vec<f64> {
    ext.drain(..edge);
    ext.truncate(n);
    ext
}

/// The moving median of `y` over `size` samples centred on each (the element of rank
/// `size / 2` of the window, sorted), the ends extended by their edge values: SciPy's
/// `ndimage.median_filter(y, size=size, mode="nearest")` of a signal, value for value
/// (a median selects, it computes nothing). The window is kept sorted: each step
/// removes the sample that leaves and inserts the one that enters.
pub fn moving_median(y: &[f64], size: usize) -> Vec<f64> {
    let n = y.len();
    if n == 0 || size <= 1 {
        return y.to_vec();
    }
    let half = size / 2;
    // the sample at extended index j (j - half into y, clamped to its ends)
    let at = |j: usize| y[j.saturating_sub(half).min(n - 1)];
    let mut win: Vec<f64> = (0..size).map(at).collect();
    win.sort_by(f64::total_cmp);
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        out.push(win[half]);
        if i + 1 == n {
            break;
        }
        let leave = at(i);
        let k = win.partition_point(|v| v.total_cmp(&leave).is_lt());
        win.remove(k);
        let enter = at(i + size);
        let k = win.partition_point(|v| v.total_cmp(&enter).is_lt());
        win.insert(k, enter);
    }
    out
}

#[cfg(test)]
mod tests {
    #[test]
    fn moving_median_selects_the_middle_of_each_window() {
        let y = [5.0, 1.0, 4.0, 2.0, 3.0, 9.0, -1.0];
        // windows of 3, ends extended: [5 5 1] [5 1 4] [1 4 2] [4 2 3] [2 3 9] [3 9 -1] [9 -1 -1]
        assert_eq!(
            super::moving_median(&y, 3),
            vec![5.0, 4.0, 2.0, 3.0, 3.0, 3.0, -1.0]
        );
        assert_eq!(super::moving_median(&y[..1], 11), vec![5.0]);
        assert!(super::moving_median(&[], 5).is_empty());
    }

    use super::*;

    #[test]
    fn constant_passes_unchanged() {
        // a second-order Butterworth at 0.1 of Nyquist (scipy.signal.butter(2, 0.1))
        let s = [
            0.020083365564211232,
            0.040166731128422464,
            0.020083365564211232,
            1.0,
            -1.5610180758007182,
            0.6413515380575631,
        ];
        let f = Lowpass::new(vec![s], 9).unwrap();
        let y = f.filtfilt(&[3.5; 50]);
        for v in y {
            assert!((v - 3.5).abs() < 1e-12, "{v}");
        }
    }

    #[test]
    fn a_pulse_decays_to_zero_not_through_subnormals() {
        // a pulse, then 20 000 zeros: without the flush the states fall through the
        // subnormal numbers and cycle among the smallest of them to the end
        let s = [
            0.020083365564211232,
            0.040166731128422464,
            0.020083365564211232,
            1.0,
            -1.5610180758007182,
            0.6413515380575631,
        ];
        let mut y = vec![0.0; 20_000];
        y[100] = 1.0;
        for sections in [vec![s, s], vec![s; 5]] {
            let f = Lowpass::new(sections, 12).unwrap();
            let out = f.filtfilt(&y);
            assert!(out
                .iter()
                .all(|v| *v == 0.0 || v.abs() >= f64::MIN_POSITIVE));
            assert!(out[19_000..].iter().all(|v| *v == 0.0));
            // where the signal is far above the flush level, the plain cascade's numbers
            let mut plain = Lowpass::identity();
            plain.sections = f.sections.clone();
            plain.zi = f.zi.clone();
            let mut fw = y.clone();
            let mut st = vec![[0.0f64; 2]; plain.sections.len()];
            for pass in 0..2 {
                let idx: Vec<usize> = if pass == 0 {
                    (0..fw.len()).collect()
                } else {
                    (0..fw.len()).rev().collect()
                };
                st.iter_mut().for_each(|s| *s = [0.0, 0.0]);
                for k in idx {
                    let mut x = fw[k];
                    for (c, s) in plain.sections.iter().zip(st.iter_mut()) {
                        let o = c[0] * x + s[0];
                        s[0] = c[1] * x - c[4] * o + s[1];
                        s[1] = c[2] * x - c[5] * o;
                        x = o;
                    }
                    fw[k] = x;
                }
            }
            for (a, b) in out.iter().zip(&fw) {
                assert!(b.abs() < 1e-250 || a == b, "{a} {b}");
            }
        }
    }

    #[test]
    fn side_by_side_as_one_at_a_time() {
        let s = [
            0.020083365564211232,
            0.040166731128422464,
            0.020083365564211232,
            1.0,
            -1.5610180758007182,
            0.6413515380575631,
        ];
        let sig = |j: usize, n: usize| -> Vec<f64> {
            (0..n)
                .map(|k| ((k * (j + 3)) as f64 * 0.01).sin() + if k == 40 { 1e3 } else { 0.0 })
                .collect()
        };
        // lengths 1, 7 (shorter than the extension) and 300; groups of 1 to 4 and 5
        let ys: Vec<Vec<f64>> = (0..14)
            .map(|j| sig(j, [300, 7, 300, 1, 300][j % 5]))
            .collect();
        let refs: Vec<&[f64]> = ys.iter().map(|y| y.as_slice()).collect();
        for n in 1..=5 {
            let f = Lowpass::new(vec![s; n], 9).unwrap();
            for take in [2, 3, 4, 5, 14] {
                let many = f.filtfilt_many(&refs[..take]);
                assert_eq!(many.len(), take);
                for (y, got) in refs.iter().zip(&many) {
                    let one = f.filtfilt(y);
                    assert!(one.iter().zip(got).all(|(a, b)| a.to_bits() == b.to_bits()));
                    assert_eq!(one.len(), got.len());
                }
            }
        }
        assert!(Lowpass::identity().filtfilt_many(&refs)[3] == ys[3]);
        // read where they are (the columns of a row-major matrix), 1 to 4 at a time,
        // with 2 and 5 sections (5: one at a time) and none
        let n = 300;
        let rows: Vec<[f64; 4]> = (0..n)
            .map(|k| core::array::from_fn(|j| sig(j, n)[k]))
            .collect();
        for f in [
            Lowpass::new(vec![s; 2], 9).unwrap(),
            Lowpass::new(vec![s; 5], 9).unwrap(),
            Lowpass::identity(),
        ] {
            for width in 1..=LANES {
                let got = f.filtfilt_lanes(n, width, |l, k| rows[k][l]);
                assert_eq!(got.width(), width);
                for l in 0..width {
                    let one = f.filtfilt(&sig(l, n));
                    assert!(one
                        .iter()
                        .zip(got.lane(l))
                        .all(|(a, b)| a.to_bits() == b.to_bits()));
                    assert_eq!(got.lane(l).count(), n);
                }
            }
        }
    }

    #[test]
    fn line_passes_unchanged() {
        let s = [
            0.020083365564211232,
            0.040166731128422464,
            0.020083365564211232,
            1.0,
            -1.5610180758007182,
            0.6413515380575631,
        ];
        let f = Lowpass::new(vec![s, s], 12).unwrap();
        let x: Vec<f64> = (0..200).map(|k| 0.3 * k as f64 - 2.0).collect();
        let y = f.filtfilt(&x);
        // zero phase: away from the ends the forward lag and the backward lead cancel
        for (a, b) in x.iter().zip(&y).skip(80).take(40) {
            assert!((a - b).abs() < 1e-6, "{a} {b}");
        }
    }

    #[test]
    fn rejects_bad_sections() {
        assert!(Lowpass::new(vec![[1.0, 0.0, 0.0, 2.0, 0.0, 0.0]], 3).is_err());
        assert!(Lowpass::new(vec![[1.0, f64::NAN, 0.0, 1.0, 0.0, 0.0]], 3).is_err());
        assert!(Lowpass::new(vec![[1.0, 0.0, 0.0, 1.0, -2.0, 1.0]], 3).is_err());
    }
}
