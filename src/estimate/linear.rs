//! Weighted linear robust least squares by iteratively reweighted least squares (IRLS).
//!
//! The inverse-dynamics fit of a recording (`lugre fit`, Python
//! `diagnosis/inverse.py`) is linear in its unknowns for a given Stribeck speed `vs`:
//! `F = m*a + fc*sign(v) + sigma2*v + (fs - fc)*exp(-(v/vs)^2)*sign(v)`, each term
//! low-passed like the force. Its robust version is the classic M-estimate by IRLS
//! (Holland and Welsch 1977) with the seed paper's IGG weights: each round solves the
//! weighted normal equations `(X^T W X + lambda I) b = X^T W y`, then sets the weights
//! from the residuals in units of the robust scale `1.4826*MAD` ([`robust_scale`]).
//! [`irls_linear_grid`] runs it over candidate columns (one pair per `vs` of a grid) and
//! keeps the candidate whose extra coefficients are positive and whose weighted sum of
//! squares is clearly the smallest.
//!
//! Arithmetic, fixed so that the NumPy twin (`lugre.reference.irls_linear`) repeats it
//! bit for bit: every sum over rows runs in row order from the first row's term (the
//! twin's `np.add.accumulate`; NumPy's `sum` adds pairwise); the
//! normal matrix holds `(w_i*x_ij)*x_ik`; `lambda = 1e-12*trace` (a ridge that keeps a
//! column that is zero on the weighted rows from making the matrix singular: its
//! coefficient comes out 0); Gaussian elimination with partial pivoting (the first row
//! of largest magnitude); the fitted value `x_i0*b_0 + x_i1*b_1 + ...` from the left;
//! the scale `robust_scale(e) + 1e-12`.

use super::robust::{robust_scale, Weighting};
use crate::error::{Error, Result};

/// Rounds of reweighting in [`LinearIrlsOptions::default`].
pub const DEFAULT_ROUNDS: usize = 8;

/// Relative ridge added to the diagonal of the normal matrix (times its trace).
const RIDGE: f64 = 1e-12;

/// Added to the robust scale so that a perfect fit does not divide by zero.
const SCALE_FLOOR: f64 = 1e-12;

/// A design matrix stored column by column (column-major): element `(i, j)` is
/// `data[j*rows + i]`.
///
/// ```
/// use lugre::estimate::linear::Design;
/// let d = Design::new(&[1.0, 2.0, 3.0, 10.0, 20.0, 30.0], 3);
/// assert_eq!((d.rows(), d.cols()), (3, 2));
/// assert_eq!(d.column(1), &[10.0, 20.0, 30.0]);
/// ```
#[derive(Debug, Clone, Copy)]
pub struct Design<'a> {
    data: &'a [f64],
    rows: usize,
}

impl<'a> Design<'a> {
    /// The matrix of `rows` rows whose columns follow one another in `data`. Its shape
    /// is checked by the fits, which name the argument.
    pub fn new(data: &'a [f64], rows: usize) -> Self {
        Design { data, rows }
    }

    /// Number of rows.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// Number of whole columns (0 without rows).
    pub fn cols(&self) -> usize {
        self.data.len().checked_div(self.rows).unwrap_or(0)
    }

    /// Column `j` (panics when `j >= cols()`).
    pub fn column(&self, j: usize) -> &'a [f64] {
        &self.data[j * self.rows..(j + 1) * self.rows]
    }
}

/// Options of [`irls_linear`] and [`irls_linear_grid`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinearIrlsOptions {
    /// Weight function (IGG `k0 = 1.5`, `k1 = 2.5` by default).
    pub weighting: Weighting,
    /// Rounds of reweighting, at least 1 (8 by default). Each round solves the weighted
    /// problem and recomputes the weights from its residuals; there is no early stop.
    pub rounds: usize,
}

impl Default for LinearIrlsOptions {
    fn default() -> Self {
        LinearIrlsOptions {
            weighting: Weighting::igg(),
            rounds: DEFAULT_ROUNDS,
        }
    }
}

/// The result of a robust linear fit.
#[derive(Debug, Clone, PartialEq)]
pub struct LinearFit {
    /// Coefficients `b`, one per column, from the last round's weighted solve.
    pub coef: Vec<f64>,
    /// Weights of the rows from the residuals of `coef` (0 for a rejected row).
    pub weights: Vec<f64>,
    /// Residuals `y - X b`.
    pub residuals: Vec<f64>,
    /// Weighted sum of squares `sum w_i*e_i^2` (each term `(w_i*e_i)*e_i`).
    pub sse: f64,
    /// The scale the weights were computed at (`robust_scale(e) + 1e-12`).
    pub scale: f64,
}

/// The result of [`irls_linear_grid`].
#[derive(Debug, Clone, PartialEq)]
pub struct GridFit {
    /// Index of the chosen candidate in `extras`, `None` for the base design alone.
    pub chosen: Option<usize>,
    /// The chosen fit (its coefficients: the base columns', then the candidate's).
    pub fit: LinearFit,
    /// Weighted sum of squares of the base design alone.
    pub base_sse: f64,
    /// Weighted sum of squares of each candidate, in the order of `extras`.
    pub sse: Vec<f64>,
}

/// Robust linear least squares `y ~ X b` by IRLS.
///
/// Starting from unit weights, each of `opts.rounds` rounds solves
/// `(X^T W X + 1e-12*trace(X^T W X)*I) b = X^T W y`, takes the residuals
/// `e = y - X b`, the scale `s = robust_scale(e) + 1e-12` and the weights
/// `w_i = weighting(e_i/s)`. The result holds the last round's `b`, the weights and
/// residuals of that `b`, and `sum w_i*e_i^2`.
///
/// # Errors
/// [`Error::Parameter`] for bad weighting constants or `rounds == 0`;
/// [`Error::Input`] naming `X` or `y` for a design without rows or columns, fewer rows
/// than columns, `y` of another length, non-finite values, or values so large that the
/// normal equations overflow; [`Error::Data`] when the weights leave no non-zero row or
/// the normal matrix is singular.
///
/// ```
/// use lugre::estimate::linear::{irls_linear, Design, LinearIrlsOptions};
/// // y = 2 + 3 t with one gross error
/// let t: Vec<f64> = (0..20).map(|k| k as f64).collect();
/// let mut y: Vec<f64> = t.iter().map(|t| 2.0 + 3.0 * t + 0.01 * (t * 7.0).sin()).collect();
/// y[5] += 100.0;
/// let x: Vec<f64> = [vec![1.0; 20], t].concat();
/// let fit = irls_linear(Design::new(&x, 20), &y, &LinearIrlsOptions::default()).unwrap();
/// assert!((fit.coef[1] - 3.0).abs() < 1e-2 && fit.weights[5] == 0.0);
/// ```
pub fn irls_linear(x: Design<'_>, y: &[f64], opts: &LinearIrlsOptions) -> Result<LinearFit> {
    check_options(opts)?;
    let rows = x.rows;
    check_design("X", x, None)?;
    check_unknowns("X", rows, x.cols())?;
    check_target(y, rows)?;
    let columns: Vec<&[f64]> = (0..x.cols()).map(|j| x.column(j)).collect();
    fit_rows(&row_major(&columns, rows), columns.len(), y, opts)
}

/// [`irls_linear`] of the base design `X` alone and of `X` joined by each candidate's
/// extra columns (`extras[k]`, on the rows of `X`); returns the best.
///
/// The base fit is the first best. Candidates are taken in order; a candidate replaces
/// the best when every coefficient of its extra columns is greater than zero and its
/// weighted sum of squares is below `ratio` times the best's. (The inverse-dynamics fit
/// passes, for each `vs` of a grid, the Stribeck-hump columns of both directions, and
/// `ratio = 0.98`: a hump must exist in both directions and explain at least 2 % more.)
/// The fits run in parallel (rayon); the result does not depend on the threads.
///
/// # Errors
/// As [`irls_linear`], and [`Error::Parameter`] for `ratio` not in `(0, 1]`;
/// [`Error::Input`] naming `extras[k]` for a candidate of another number of rows,
/// without columns, with non-finite values or with too many columns for the rows. An
/// error of a candidate's fit names it.
pub fn irls_linear_grid(
    x: Design<'_>,
    extras: &[Design<'_>],
    y: &[f64],
    opts: &LinearIrlsOptions,
    ratio: f64,
) -> Result<GridFit> {
    use rayon::prelude::*;

    check_options(opts)?;
    if !(ratio.is_finite() && ratio > 0.0 && ratio <= 1.0) {
        return Err(Error::parameter(
            "ratio",
            ratio,
            "must be a number in (0, 1]: the fraction of the best weighted sum of squares \
             a candidate must get below",
        ));
    }
    let rows = x.rows;
    check_design("X", x, None)?;
    check_unknowns("X", rows, x.cols())?;
    check_target(y, rows)?;
    for (k, d) in extras.iter().enumerate() {
        let name = format!("extras[{k}]");
        check_design(&name, *d, Some(rows))?;
        check_unknowns(&name, rows, x.cols() + d.cols())?;
    }
    let base: Vec<&[f64]> = (0..x.cols()).map(|j| x.column(j)).collect();
    let fit_with = |extra: Option<&Design<'_>>| {
        let mut cols = base.clone();
        if let Some(d) = extra {
            cols.extend((0..d.cols()).map(|j| d.column(j)));
        }
        fit_rows(&row_major(&cols, rows), cols.len(), y, opts)
    };
    let base_fit = fit_with(None)?;
    let fits: Vec<Result<LinearFit>> = extras.par_iter().map(|d| fit_with(Some(d))).collect();
    let base_sse = base_fit.sse;
    let mut best = (None, base_fit);
    let mut sse = Vec::with_capacity(extras.len());
    for (k, f) in fits.into_iter().enumerate() {
        let f = f.map_err(|e| in_candidate(e, k))?;
        sse.push(f.sse);
        let p0 = base.len();
        let humps_positive = f.coef[p0..].iter().all(|&c| c > 0.0);
        if humps_positive && f.sse < ratio * best.1.sse {
            best = (Some(k), f);
        }
    }
    Ok(GridFit {
        chosen: best.0,
        fit: best.1,
        base_sse,
        sse,
    })
}

/// An error of candidate `k`'s fit, said to be about that candidate.
fn in_candidate(e: Error, k: usize) -> Error {
    match e {
        Error::Data(msg) => Error::Data(format!("with extras[{k}]: {msg}")),
        Error::Input { name, message } if name == "X" => Error::Input {
            name: format!("extras[{k}]"),
            message: format!("joined to X: {message}"),
        },
        other => other,
    }
}

fn check_options(opts: &LinearIrlsOptions) -> Result<()> {
    opts.weighting.validate()?;
    if opts.rounds == 0 {
        return Err(Error::parameter(
            "rounds",
            0.0,
            "must be at least 1 (rounds of reweighting)",
        ));
    }
    Ok(())
}

/// Shape and values of a design named `name`, with `rows` rows when given.
fn check_design(name: &str, d: Design<'_>, rows: Option<usize>) -> Result<()> {
    if let Some(n) = rows {
        if d.rows != n {
            return Err(Error::input(
                name,
                format!(
                    "has {} rows but X has {n}: give the candidate's columns on the rows of X",
                    d.rows
                ),
            ));
        }
    }
    if d.rows == 0 {
        return Err(Error::input(name, "has no rows: give one row per sample"));
    }
    if d.data.len() % d.rows != 0 {
        return Err(Error::input(
            name,
            format!(
                "has {} values, not a whole number of columns of {} rows: give the \
                 matrix column by column",
                d.data.len(),
                d.rows
            ),
        ));
    }
    if d.cols() == 0 {
        return Err(Error::input(
            name,
            "has no columns: give at least one regressor",
        ));
    }
    if let Some(k) = d.data.iter().position(|v| !v.is_finite()) {
        return Err(Error::input(
            name,
            format!(
                "row {}, column {} is {} : remove or interpolate non-finite samples",
                k % d.rows,
                k / d.rows,
                d.data[k]
            ),
        ));
    }
    Ok(())
}

/// At least as many rows as unknowns.
fn check_unknowns(name: &str, rows: usize, unknowns: usize) -> Result<()> {
    if rows < unknowns {
        return Err(Error::input(
            name,
            format!(
                "gives {unknowns} unknowns for {rows} rows: give at least as many rows \
                 (samples) as columns (unknowns)"
            ),
        ));
    }
    Ok(())
}

fn check_target(y: &[f64], rows: usize) -> Result<()> {
    if y.len() != rows {
        return Err(Error::input(
            "y",
            format!(
                "has {} samples but X has {rows} rows: give one target per row of X",
                y.len()
            ),
        ));
    }
    crate::error::check_finite("y", y)
}

/// The columns as one row-major matrix (`p` values per row).
fn row_major(cols: &[&[f64]], rows: usize) -> Vec<f64> {
    let p = cols.len();
    let mut out = vec![0.0; rows * p];
    for (j, c) in cols.iter().enumerate() {
        for (i, v) in c.iter().enumerate() {
            out[i * p + j] = *v;
        }
    }
    out
}

/// The IRLS rounds on a checked, row-major design of `p` columns.
fn fit_rows(xr: &[f64], p: usize, y: &[f64], opts: &LinearIrlsOptions) -> Result<LinearFit> {
    let n = y.len();
    let mut w = vec![1.0; n];
    let mut coef = vec![0.0; p];
    let mut e = vec![0.0; n];
    let mut s = 0.0;
    for round in 0..opts.rounds {
        let (mut g, rhs) = normal_equations(xr, p, y, &w);
        let mut trace = g[0];
        for j in 1..p {
            trace += g[j * p + j];
        }
        if !trace.is_finite() {
            return Err(Error::input(
                "X",
                format!(
                    "its normal matrix overflows (trace {trace}): scale the columns of X \
                     to moderate values"
                ),
            ));
        }
        if trace == 0.0 {
            return Err(if round == 0 {
                Error::input(
                    "X",
                    "is zero in every row: give at least one non-zero regressor",
                )
            } else {
                Error::Data(format!(
                    "the {} weights keep no row in which X is non-zero (round {} of {}): \
                     check y for gross errors in most rows, or use weighting \"huber\"",
                    opts.weighting.name(),
                    round + 1,
                    opts.rounds
                ))
            });
        }
        if let Some(j) = rhs.iter().position(|v| !v.is_finite()) {
            return Err(Error::input(
                "y",
                format!(
                    "the fit overflows (X^T W y is {} in column {j}): scale y and the \
                     columns of X to moderate values",
                    rhs[j]
                ),
            ));
        }
        let lambda = RIDGE * trace;
        for j in 0..p {
            g[j * p + j] += lambda;
        }
        coef = solve(g, rhs, p).ok_or_else(|| {
            Error::Data(format!(
                "the weighted normal matrix of X is singular (round {} of {}): drop \
                 columns of X that are combinations of others",
                round + 1,
                opts.rounds
            ))
        })?;
        residuals_into(xr, p, y, &coef, &mut e);
        if let Some(k) = e.iter().position(|v| !v.is_finite()) {
            return Err(Error::input(
                "y",
                format!(
                    "the fit overflows (residual {k} is {}): scale y and the columns of X \
                     to moderate values",
                    e[k]
                ),
            ));
        }
        s = robust_scale(&e) + SCALE_FLOOR;
        w = opts.weighting.weights(&e, s);
    }
    let mut sse = -0.0;
    for (wi, ei) in w.iter().zip(&e) {
        sse += (wi * ei) * ei;
    }
    Ok(LinearFit {
        coef,
        weights: w,
        residuals: e,
        sse,
        scale: s,
    })
}

/// `X^T W X` (row-major `p x p`) and `X^T W y`, each sum in row order from the first
/// row's term (accumulators start at `-0.0`, the exact identity of addition): the upper
/// triangle summed, the lower mirrored. Unrolled for up to 8 columns.
fn normal_equations(xr: &[f64], p: usize, y: &[f64], w: &[f64]) -> (Vec<f64>, Vec<f64>) {
    match p {
        1 => normal_fixed::<1>(xr, y, w),
        2 => normal_fixed::<2>(xr, y, w),
        3 => normal_fixed::<3>(xr, y, w),
        4 => normal_fixed::<4>(xr, y, w),
        5 => normal_fixed::<5>(xr, y, w),
        6 => normal_fixed::<6>(xr, y, w),
        7 => normal_fixed::<7>(xr, y, w),
        8 => normal_fixed::<8>(xr, y, w),
        _ => normal_any(xr, p, y, w),
    }
}

fn normal_fixed<const P: usize>(xr: &[f64], y: &[f64], w: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let mut g = [[-0.0f64; P]; P];
    let mut rhs = [-0.0f64; P];
    for ((xi, yi), wi) in xr.chunks_exact(P).zip(y).zip(w) {
        let mut x = [0.0f64; P];
        x.copy_from_slice(xi);
        for j in 0..P {
            let a = wi * x[j];
            rhs[j] += a * yi;
            for k in j..P {
                g[j][k] += a * x[k];
            }
        }
    }
    let mut out = vec![0.0; P * P];
    for j in 0..P {
        for k in 0..P {
            out[j * P + k] = if k >= j { g[j][k] } else { g[k][j] };
        }
    }
    (out, rhs.to_vec())
}

fn normal_any(xr: &[f64], p: usize, y: &[f64], w: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let mut g = vec![-0.0; p * p];
    let mut rhs = vec![-0.0; p];
    for ((xi, yi), wi) in xr.chunks_exact(p).zip(y).zip(w) {
        for j in 0..p {
            let a = wi * xi[j];
            rhs[j] += a * yi;
            for (gk, xk) in g[j * p + j..(j + 1) * p].iter_mut().zip(&xi[j..]) {
                *gk += a * xk;
            }
        }
    }
    for j in 0..p {
        for k in 0..j {
            g[j * p + k] = g[k * p + j];
        }
    }
    (g, rhs)
}

/// `e_i = y_i - (x_i0*b_0 + x_i1*b_1 + ...)`, the sum from the left.
fn residuals_into(xr: &[f64], p: usize, y: &[f64], b: &[f64], e: &mut [f64]) {
    for ((ei, xi), yi) in e.iter_mut().zip(xr.chunks_exact(p)).zip(y) {
        let mut f = xi[0] * b[0];
        for j in 1..p {
            f += xi[j] * b[j];
        }
        *ei = yi - f;
    }
}

/// Solve `a x = b` (`a` row-major `p x p`) by Gaussian elimination with partial
/// pivoting (the first row of largest magnitude); `None` for a zero or non-finite
/// pivot or a non-finite solution.
fn solve(mut a: Vec<f64>, mut b: Vec<f64>, p: usize) -> Option<Vec<f64>> {
    for k in 0..p {
        let mut piv = k;
        let mut big = a[k * p + k].abs();
        for i in k + 1..p {
            let v = a[i * p + k].abs();
            if v > big {
                big = v;
                piv = i;
            }
        }
        if !(big > 0.0 && big.is_finite()) {
            return None;
        }
        if piv != k {
            for j in 0..p {
                a.swap(k * p + j, piv * p + j);
            }
            b.swap(k, piv);
        }
        let d = a[k * p + k];
        for i in k + 1..p {
            let f = a[i * p + k] / d;
            for j in k + 1..p {
                a[i * p + j] -= f * a[k * p + j];
            }
            b[i] -= f * b[k];
        }
    }
    let mut x = vec![0.0; p];
    for k in (0..p).rev() {
        let mut s = b[k];
        for j in k + 1..p {
            s -= a[k * p + j] * x[j];
        }
        x[k] = s / a[k * p + k];
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn line(n: usize) -> (Vec<f64>, Vec<f64>) {
        let t: Vec<f64> = (0..n).map(|k| k as f64 / n as f64).collect();
        let y = t
            .iter()
            .map(|t| 1.0 - 2.0 * t + 0.01 * (37.0 * t).sin())
            .collect();
        ([vec![1.0; n], t].concat(), y)
    }

    #[test]
    fn solves_a_small_system_exactly() {
        // [[2, 1], [1, 3]] x = [3, 5] -> x = [0.8, 1.4]
        let x = solve(vec![2.0, 1.0, 1.0, 3.0], vec![3.0, 5.0], 2).unwrap();
        assert!((x[0] - 0.8).abs() < 1e-15 && (x[1] - 1.4).abs() < 1e-15);
        assert!(solve(vec![0.0, 0.0, 0.0, 0.0], vec![1.0, 1.0], 2).is_none());
        // pivoting: a zero in the first pivot position
        let x = solve(vec![0.0, 1.0, 1.0, 0.0], vec![2.0, 3.0], 2).unwrap();
        assert_eq!(x, vec![3.0, 2.0]);
    }

    #[test]
    fn rejects_a_gross_error_that_pulls_least_squares() {
        let (x, mut y) = line(40);
        y[7] += 50.0;
        let robust = irls_linear(Design::new(&x, 40), &y, &LinearIrlsOptions::default()).unwrap();
        let ls = irls_linear(
            Design::new(&x, 40),
            &y,
            &LinearIrlsOptions {
                weighting: Weighting::None,
                rounds: 1,
            },
        )
        .unwrap();
        assert_eq!(robust.weights[7], 0.0);
        assert!((robust.coef[0] - 1.0).abs() < 0.02, "{:?}", robust.coef);
        assert!((ls.coef[0] - 1.0).abs() > 0.5, "{:?}", ls.coef);
    }

    #[test]
    fn errors_name_the_argument() {
        let (x, y) = line(10);
        let o = LinearIrlsOptions::default();
        let name = |r: Result<LinearFit>| match r.unwrap_err() {
            Error::Input { name, .. } | Error::Parameter { name, .. } => name,
            e => panic!("{e}"),
        };
        assert_eq!(name(irls_linear(Design::new(&x, 10), &y[..9], &o)), "y");
        assert_eq!(name(irls_linear(Design::new(&x[..19], 10), &y, &o)), "X");
        assert_eq!(name(irls_linear(Design::new(&x, 0), &y, &o)), "X");
        assert_eq!(name(irls_linear(Design::new(&x[..3], 1), &y[..1], &o)), "X");
        let mut bad = x.clone();
        bad[13] = f64::NAN;
        let e = irls_linear(Design::new(&bad, 10), &y, &o).unwrap_err();
        assert!(e.to_string().contains("row 3, column 1 is NaN"), "{e}");
        let zero = vec![0.0; 20];
        let e = irls_linear(Design::new(&zero, 10), &y, &o).unwrap_err();
        assert!(e.to_string().contains("zero in every row"), "{e}");
        let o0 = LinearIrlsOptions { rounds: 0, ..o };
        assert_eq!(name(irls_linear(Design::new(&x, 10), &y, &o0)), "rounds");
        let e = irls_linear_grid(Design::new(&x, 10), &[], &y, &o, 1.5).unwrap_err();
        assert!(e.to_string().contains("ratio"), "{e}");
        let short = [1.0; 9];
        let e = irls_linear_grid(Design::new(&x, 10), &[Design::new(&short, 9)], &y, &o, 0.98);
        assert!(e.unwrap_err().to_string().contains("extras[0]: has 9 rows"));
    }

    #[test]
    fn grid_keeps_a_candidate_only_with_positive_extras() {
        let (x, y) = line(50);
        let t = &x[50..];
        // a column that explains the wiggle with a positive coefficient, and its negative
        let good: Vec<f64> = t.iter().map(|t| (37.0 * t).sin()).collect();
        let bad: Vec<f64> = good.iter().map(|v| -v).collect();
        let o = LinearIrlsOptions::default();
        let g = irls_linear_grid(
            Design::new(&x, 50),
            &[Design::new(&bad, 50), Design::new(&good, 50)],
            &y,
            &o,
            0.98,
        )
        .unwrap();
        assert_eq!(g.chosen, Some(1));
        assert!((g.fit.coef[2] - 0.01).abs() < 1e-9);
        assert!(g.sse[0] < 1e-12 && g.sse[1] < 1e-12 && g.base_sse > 1e-4);
    }
}
