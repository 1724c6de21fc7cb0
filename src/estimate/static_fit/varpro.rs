//! Variable projection (separable least squares, Golub and Pereyra 1973): for a fixed
//! `vs` the Stribeck curve is linear in `(fc, fs - fc, sigma2)`, solved in closed form
//! from the 3x3 normal equations with the signs kept by an exhaustive active set, so
//! the nonlinear search is over `ln vs` alone.

use super::super::nelder_mead::{minimize, NmOptions};

/// `g(a) + sigma2*a` for a speed magnitude `a`.
#[inline]
pub(super) fn curve(p: &[f64; 4], a: f64) -> f64 {
    let r = a / p[3];
    p[0] + (p[1] - p[0]) * (-(r * r)).exp() + p[2] * a
}

/// The Stribeck shape `phi_i = exp(-(a_i/vs)^2)` of every point.
#[inline]
pub(super) fn fill_phi(a: &[f64], vs: f64, phi: &mut [f64]) {
    let iv = 1.0 / vs;
    for (p, &ai) in phi.iter_mut().zip(a) {
        let r = ai * iv;
        // below exp(-40) = 4e-18 the term is under the rounding of the force
        *p = if r * r < 40.0 { (-(r * r)).exp() } else { 0.0 };
    }
}

/// Weighted normal equations of the linear part for fixed `vs`: columns
/// `(1, phi, a)`, unknowns `(fc - fc_min, fs - fc, sigma2)`.
#[derive(Clone, Copy, Default)]
pub(super) struct Normal {
    pub(super) m: [[f64; 3]; 3],
    pub(super) b: [f64; 3],
}

impl Normal {
    #[inline]
    pub(super) fn add(&mut self, phi: f64, a: f64, y: f64, w: f64) {
        let (wp, wa) = (w * phi, w * a);
        self.m[0][0] += w;
        self.m[0][1] += wp;
        self.m[0][2] += wa;
        self.m[1][1] += wp * phi;
        self.m[1][2] += wp * a;
        self.m[2][2] += wa * a;
        self.b[0] += w * y;
        self.b[1] += wp * y;
        self.b[2] += wa * y;
    }

    /// Solve on the free unknowns (`free` bit k set) with the others held at zero, by
    /// Cholesky of the column-scaled system (unit diagonal); `None` when (nearly)
    /// singular.
    pub(super) fn solve_free(&self, free: u8) -> Option<[f64; 3]> {
        const PIVOT: f64 = 1e-13;
        let m = &self.m;
        let inv_sqrt = |v: f64| (v > 0.0 && v.is_finite()).then(|| 1.0 / v.sqrt());
        let mut x = [0.0; 3];
        match free {
            0b111 => {
                let (d0, d1, d2) = (inv_sqrt(m[0][0])?, inv_sqrt(m[1][1])?, inv_sqrt(m[2][2])?);
                let (a, b, c) = (m[0][1] * d0 * d1, m[0][2] * d0 * d2, m[1][2] * d1 * d2);
                let p1 = 1.0 - a * a;
                if p1.is_nan() || p1 <= PIVOT {
                    return None;
                }
                let l11 = p1.sqrt();
                let l21 = (c - a * b) / l11;
                let p2 = 1.0 - b * b - l21 * l21;
                if p2.is_nan() || p2 <= PIVOT {
                    return None;
                }
                let l22 = p2.sqrt();
                let z0 = self.b[0] * d0;
                let z1 = (self.b[1] * d1 - a * z0) / l11;
                let z2 = (self.b[2] * d2 - b * z0 - l21 * z1) / l22;
                let u2 = z2 / l22;
                let u1 = (z1 - l21 * u2) / l11;
                let u0 = z0 - a * u1 - b * u2;
                x = [u0 * d0, u1 * d1, u2 * d2];
            }
            0b011 | 0b101 | 0b110 => {
                let (i, j) = match free {
                    0b011 => (0, 1),
                    0b101 => (0, 2),
                    _ => (1, 2),
                };
                let (di, dj) = (inv_sqrt(m[i][i])?, inv_sqrt(m[j][j])?);
                let a = m[i][j] * di * dj;
                let det = 1.0 - a * a;
                if det.is_nan() || det <= PIVOT {
                    return None;
                }
                let (bi, bj) = (self.b[i] * di, self.b[j] * dj);
                x[i] = (bi - a * bj) / det * di;
                x[j] = (bj - a * bi) / det * dj;
            }
            0b001 | 0b010 | 0b100 => {
                let i = free.trailing_zeros() as usize;
                let mii = m[i][i];
                if !(mii > 0.0 && mii.is_finite()) {
                    return None;
                }
                x[i] = self.b[i] / mii;
            }
            _ => {}
        }
        x.iter().all(|v| v.is_finite()).then_some(x)
    }

    /// `x^T M x - 2 x^T b` (the weighted sum of squares up to a constant).
    pub(super) fn quad(&self, x: &[f64; 3]) -> f64 {
        let m = &self.m;
        let mx = [
            m[0][0] * x[0] + m[0][1] * x[1] + m[0][2] * x[2],
            m[0][1] * x[0] + m[1][1] * x[1] + m[1][2] * x[2],
            m[0][2] * x[0] + m[1][2] * x[1] + m[2][2] * x[2],
        ];
        (0..3).map(|k| x[k] * (mx[k] - 2.0 * self.b[k])).sum()
    }

    /// Least squares with every unknown nonnegative (`fc >= fc_min`, `fs >= fc`,
    /// `sigma2 >= 0`): the unconstrained solution when it is feasible, else the best
    /// feasible solution over the faces (an exhaustive active set; three unknowns).
    pub(super) fn solve_nonneg(&self) -> [f64; 3] {
        if let Some(x) = self.solve_free(0b111) {
            if x.iter().all(|v| *v >= 0.0) {
                return x;
            }
        }
        let mut best = ([0.0; 3], 0.0);
        for free in [0b011u8, 0b101, 0b110, 0b001, 0b010, 0b100] {
            if let Some(x) = self.solve_free(free) {
                if x.iter().all(|v| *v >= 0.0) {
                    let q = self.quad(&x);
                    if q < best.1 {
                        best = (x, q);
                    }
                }
            }
        }
        best.0
    }
}

/// One direction's points and work buffers of the separable (variable projection)
/// problem: for fixed `vs` the curve is linear in `(fc, fs - fc, sigma2)`, solved in
/// closed form, so the nonlinear search is over `ln vs` alone (Golub and Pereyra 1973).
pub(super) struct Sep<'a> {
    pub(super) a: &'a [f64],
    pub(super) y: &'a [f64],
    /// Smallest `fc` (a tiny positive force: the model needs `fc > 0`).
    pub(super) fc_min: f64,
    /// Search interval of `ln vs` (the profile is flat far outside the speed range).
    pub(super) ln_lo: f64,
    pub(super) ln_hi: f64,
    pub(super) phi: Vec<f64>,
}

impl<'a> Sep<'a> {
    pub(super) fn new(a: &'a [f64], y: &'a [f64], fscale: f64) -> Self {
        let amin = a.iter().copied().fold(f64::INFINITY, f64::min);
        let amax = a.iter().copied().fold(0.0, f64::max);
        Self {
            a,
            y,
            fc_min: 1e-9 * fscale,
            ln_lo: amin.ln() - 7.0,
            ln_hi: amax.ln() + 7.0,
            phi: vec![0.0; a.len()],
        }
    }

    /// Normal equations at the `phi` in the buffer.
    pub(super) fn normal(&self, w: &[f64]) -> Normal {
        let mut ne = Normal::default();
        for (((&phi, &a), &y), &wi) in self.phi.iter().zip(self.a).zip(self.y).zip(w) {
            if wi != 0.0 {
                ne.add(phi, a, y - self.fc_min, wi);
            }
        }
        ne
    }

    pub(super) fn params(&self, x: &[f64; 3], vs: f64) -> [f64; 4] {
        let fc = self.fc_min + x[0];
        [fc, fc + x[1], x[2], vs]
    }

    /// The variable-projection objective: the weighted sum of squares at the best
    /// linear parameters for `vs = exp(ln_vs)`, and the four parameters.
    pub(super) fn profile(&mut self, w: &[f64], ln_vs: f64) -> (f64, [f64; 4]) {
        let vs = ln_vs.exp();
        if !(ln_vs >= self.ln_lo && ln_vs <= self.ln_hi) {
            return (f64::INFINITY, [f64::NAN; 4]);
        }
        fill_phi(self.a, vs, &mut self.phi);
        let x = self.normal(w).solve_nonneg();
        let p = self.params(&x, vs);
        let d = p[1] - p[0];
        let mut ss = 0.0;
        for (((&phi, &a), &y), &wi) in self.phi.iter().zip(self.a).zip(self.y).zip(w) {
            let e = y - (p[0] + d * phi + p[2] * a);
            ss += wi * e * e;
        }
        (ss, p)
    }

    pub(super) fn residuals(&self, p: &[f64; 4]) -> Vec<f64> {
        self.a
            .iter()
            .zip(self.y)
            .map(|(&ai, &yi)| yi - curve(p, ai))
            .collect()
    }
}

/// Minimum of the weighted profile over `ln vs` by Nelder-Mead from `ln_vs0`.
/// Returns the parameters and the evaluations used.
pub(super) fn vp_minimize(
    sep: &mut Sep,
    w: &[f64],
    ln_vs0: f64,
    step: f64,
    nm: &NmOptions,
    floor: f64,
) -> ([f64; 4], usize) {
    // `floor` (a constant) makes the relative stopping rule of the simplex absolute
    // near a zero sum of squares (noise-free data)
    let mut f = |x: f64| sep.profile(w, x).0 + floor;
    // bracket: three nodes `step` apart, moved downhill with a doubling step until
    // the middle one is the lowest
    let (mut xa, mut xb, mut xc) = (ln_vs0 - step, ln_vs0, ln_vs0 + step);
    let (mut fa, mut fb, mut fc) = (f(xa), f(xb), f(xc));
    let mut evals = 3;
    let mut h = step;
    while evals < 40 {
        if fa < fb && fa <= fc {
            h *= 2.0;
            (xc, fc, xb, fb) = (xb, fb, xa, fa);
            xa = xb - h;
            fa = f(xa);
        } else if fc < fb {
            h *= 2.0;
            (xa, fa, xb, fb) = (xb, fb, xc, fc);
            xc = xb + h;
            fc = f(xc);
        } else {
            break;
        }
        evals += 1;
    }
    // Nelder-Mead from the vertex of the parabola through the bracket (the best node
    // when that is not lower), with a small simplex: the parabola is close to the
    // minimum of the smooth profile, and the simplex expands if it is not
    let (da, dc) = (xb - xa, xb - xc);
    let den = da * (fb - fc) - dc * (fb - fa);
    let mut x0 = xb;
    if den != 0.0 && den.is_finite() {
        let xp = xb - 0.5 * (da * da * (fb - fc) - dc * dc * (fb - fa)) / den;
        if xp > xa && xp < xc {
            let fp = f(xp);
            evals += 1;
            if fp < fb {
                x0 = xp;
            }
        }
    }
    let simplex = (1e-3 * h).max(1e-7);
    let mut g = |x: &[f64]| f(x[0]);
    let r = minimize(&mut g, &[x0], &[simplex], nm);
    let (_, p) = sep.profile(w, r.x[0]);
    (p, evals + r.evals + 1)
}
