//! The base model identified on the inverse-dynamics residual: mass and per-direction
//! LuGre friction by robust (IGG-weighted) Levenberg-Marquardt from several starts.
//!
//! The residual is [`Record::residual`] (the bristle state driven by the measured
//! motion) and the Jacobian [`Record::base_sensitivities`], so the fit minimises the
//! very figure `evaluate` reports. The mass, `fc`, `vs` and `sigma0` are searched on a
//! log scale (`theta = exp(u)`: positive, scale-free); the hump `fs - fc` (which keeps
//! `fs >= fc`), `sigma2` and `sigma1`, which may be zero, on a linear scale projected on
//! `theta >= 0` (on a log scale a parameter near zero has a vanishing step and stays
//! there: a viscous slope taken up by `fc` at the start was never given back).

use super::{BaseParam, Record};
use crate::error::{Error, Result};
use crate::estimate::{robust_scale, Weighting};
use crate::friction::{LugreParams, StaticSet};
use crate::servo::Model;
use nalgebra::{DMatrix, DVector};

/// A parameter of the base fit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FitParam {
    /// `axis.mass` [kg].
    Mass,
    /// `fc` of a set (`true`: positive); `fs` moves with it (the hump is held).
    Fc(bool),
    /// `fs - fc` of a set.
    Hump(bool),
    /// `sigma2` of a set.
    Sigma2(bool),
    /// `vs` of a set.
    Vs(bool),
    /// `sigma0`.
    Sigma0,
    /// `sigma1`.
    Sigma1,
}

impl FitParam {
    /// Parse `mass`, `sigma0`, `sigma1` or `positive|negative.fc|hump|sigma2|vs` (the
    /// paths of [`BaseParam::parse`], with `hump` for `fs - fc` and without `fs`).
    pub fn parse(name: &str) -> Result<FitParam> {
        let bad = || {
            Error::input(
                "names",
                format!(
                    "unknown base parameter {name:?}: use mass, sigma0, sigma1 or \
                     positive/negative.fc, .hump, .sigma2, .vs"
                ),
            )
        };
        if name == "mass" {
            return Ok(FitParam::Mass);
        }
        if let Some(side) = name.strip_suffix(".hump") {
            return match BaseParam::parse(&format!("{side}.fc")) {
                Ok(BaseParam::Fc(p)) => Ok(FitParam::Hump(p)),
                _ => Err(bad()),
            };
        }
        match BaseParam::parse(name).map_err(|_| bad())? {
            BaseParam::Fc(p) => Ok(FitParam::Fc(p)),
            BaseParam::Sigma2(p) => Ok(FitParam::Sigma2(p)),
            BaseParam::Vs(p) => Ok(FitParam::Vs(p)),
            BaseParam::Sigma0 => Ok(FitParam::Sigma0),
            BaseParam::Sigma1 => Ok(FitParam::Sigma1),
            BaseParam::Fs(_) => Err(bad()),
        }
    }

    /// The sensitivity columns whose sum is its column (none for the mass: the
    /// acceleration); `fc` moves `fs` with it.
    fn columns(self) -> &'static [BaseParam] {
        use BaseParam as B;
        match self {
            FitParam::Mass => &[],
            FitParam::Fc(true) => &[B::Fc(true), B::Fs(true)],
            FitParam::Fc(false) => &[B::Fc(false), B::Fs(false)],
            FitParam::Hump(true) => &[B::Fs(true)],
            FitParam::Hump(false) => &[B::Fs(false)],
            FitParam::Sigma2(true) => &[B::Sigma2(true)],
            FitParam::Sigma2(false) => &[B::Sigma2(false)],
            FitParam::Vs(true) => &[B::Vs(true)],
            FitParam::Vs(false) => &[B::Vs(false)],
            FitParam::Sigma0 => &[B::Sigma0],
            FitParam::Sigma1 => &[B::Sigma1],
        }
    }

    /// Its value in `m`.
    pub fn get(self, m: &Model) -> f64 {
        let f = &m.friction;
        let set = |p: bool| if p { &f.positive } else { &f.negative };
        match self {
            FitParam::Mass => m.axis.mass,
            FitParam::Fc(p) => set(p).fc,
            FitParam::Hump(p) => set(p).fs - set(p).fc,
            FitParam::Sigma2(p) => set(p).sigma2,
            FitParam::Vs(p) => set(p).vs,
            FitParam::Sigma0 => f.sigma0,
            FitParam::Sigma1 => f.sigma1,
        }
    }

    /// Set its value in `m` (`fs` follows `fc` and the hump).
    pub fn set(self, m: &mut Model, value: f64) {
        fn set(f: &mut LugreParams<f64>, p: bool) -> &mut StaticSet<f64> {
            if p {
                &mut f.positive
            } else {
                &mut f.negative
            }
        }
        let f = &mut m.friction;
        match self {
            FitParam::Mass => m.axis.mass = value,
            FitParam::Fc(p) => {
                let s = set(f, p);
                let hump = s.fs - s.fc;
                s.fc = value;
                s.fs = value + hump;
            }
            FitParam::Hump(p) => {
                let s = set(f, p);
                s.fs = s.fc + value;
            }
            FitParam::Sigma2(p) => set(f, p).sigma2 = value,
            FitParam::Vs(p) => set(f, p).vs = value,
            FitParam::Sigma0 => f.sigma0 = value,
            FitParam::Sigma1 => f.sigma1 = value,
        }
    }
}

/// Settings of [`fit_base`].
#[derive(Debug, Clone, PartialEq)]
pub struct BaseFitOptions {
    /// Levenberg-Marquardt iterations per start at most.
    pub max_iter: usize,
    /// Starts followed a few iterations (the best by their first residual).
    pub scouts: usize,
    /// Iterations of those.
    pub scout_iter: usize,
    /// Starts then followed to convergence (the best scouts).
    pub keep: usize,
    /// Relative decrease of the weighted sum of squares below which a start stops (as
    /// it does when no parameter moves by 1e-5 of its scale), twice in a row.
    pub tol: f64,
    /// Weights of the residuals (Huber by default: a structured misfit such as the
    /// sticking phases is down-weighted, never rejected).
    pub weighting: Weighting,
    /// Work out [`BaseFit::information`] (one sensitivity pass more); else it is empty.
    pub information: bool,
}

impl Default for BaseFitOptions {
    fn default() -> Self {
        BaseFitOptions {
            max_iter: 60,
            scouts: 12,
            scout_iter: 6,
            keep: 3,
            tol: 1e-6,
            weighting: Weighting::huber(),
            information: true,
        }
    }
}

/// The result of [`fit_base`].
#[derive(Debug, Clone)]
pub struct BaseFit {
    /// The best model.
    pub model: Model,
    /// Its parameters' values, in the order asked.
    pub values: Vec<f64>,
    /// `sum w r^2` at the end (weights of the last round).
    pub cost: f64,
    /// The robust scale of the residual [N].
    pub scale: f64,
    /// Sum over the used samples of the weighting's loss of `r/s`, `s` the smallest
    /// scale of the starts followed: the criterion that ranks them.
    pub criterion: f64,
    /// Weights of the samples (0 outside the mask and for rejected ones).
    pub weights: Vec<f64>,
    /// `J^T W J` in the parameters themselves (not their logs), row-major, `q x q`
    /// (empty unless [`BaseFitOptions::information`]).
    pub information: Vec<f64>,
    /// Index of the start it came from.
    pub start: usize,
    /// Levenberg-Marquardt iterations of that start.
    pub iterations: usize,
    /// Residual evaluations over all starts.
    pub evaluations: usize,
}

/// The linear scale of a parameter that may be zero (`theta = scale*u`, `u >= 0`);
/// None for the log scale.
fn scale_of(p: FitParam, m: &Model, vmax: f64) -> Option<f64> {
    let f = &m.friction;
    let fc = f.positive.fc.max(f.negative.fc).max(1e-9);
    match p {
        FitParam::Hump(_) => Some(fc),
        FitParam::Sigma2(_) => Some(fc / vmax.max(1e-9)),
        FitParam::Sigma1 => Some((f.sigma0 * m.total_mass().max(1e-9)).sqrt()),
        _ => None,
    }
}

/// The loss whose minimum the weights seek, at `u = r/s`: Huber's for Huber weights,
/// else the square cut at 2.5 (IGG's rejection point).
fn loss(w: &Weighting, u: f64) -> f64 {
    let a = u.abs();
    match *w {
        Weighting::Huber { c } if a > c => c * a - 0.5 * c * c,
        Weighting::Huber { .. } => 0.5 * a * a,
        _ => 0.5 * a.min(2.5) * a.min(2.5),
    }
}

/// One start followed by IGG-weighted Levenberg-Marquardt.
struct Run {
    model: Model,
    r: Vec<f64>,
    w: Vec<f64>,
    cost: f64,
    scale: f64,
    iterations: usize,
    /// It stopped because it converged (not at its iteration limit or a refused step).
    converged: bool,
}

struct Problem<'a> {
    rec: &'a Record,
    mask: &'a [bool],
    params: &'a [FitParam],
    scales: Vec<Option<f64>>,
    opts: &'a BaseFitOptions,
    evaluations: usize,
}

impl Problem<'_> {
    /// The residual at the masked samples (0 elsewhere); None when not finite.
    fn residual(&mut self, m: &Model) -> Result<Option<Vec<f64>>> {
        self.evaluations += 1;
        let mut r = self.rec.residual(m)?;
        for (x, &keep) in r.iter_mut().zip(self.mask) {
            if !keep {
                *x = 0.0;
            }
        }
        Ok(r.iter().all(|x| x.is_finite()).then_some(r))
    }

    fn weights(&self, r: &[f64]) -> (Vec<f64>, f64) {
        let used: Vec<f64> = r
            .iter()
            .zip(self.mask)
            .filter(|(_, &k)| k)
            .map(|(x, _)| *x)
            .collect();
        let s = robust_scale(&used).max(1e-300);
        let mut w = self.opts.weighting.weights(r, s);
        for (x, &keep) in w.iter_mut().zip(self.mask) {
            if !keep {
                *x = 0.0;
            }
        }
        (w, s)
    }

    fn encode(&self, m: &Model) -> Vec<f64> {
        self.params
            .iter()
            .zip(&self.scales)
            .map(|(p, sc)| match sc {
                None => p.get(m).max(1e-300).ln(),
                Some(s) => p.get(m).max(0.0) / s,
            })
            .collect()
    }

    fn decode(&self, base: &Model, u: &[f64]) -> Model {
        let mut m = base.clone();
        for ((p, sc), &ui) in self.params.iter().zip(&self.scales).zip(u) {
            p.set(&mut m, self.value(*sc, ui));
        }
        m
    }

    fn value(&self, scale: Option<f64>, u: f64) -> f64 {
        match scale {
            None => u.exp(),
            Some(s) => s * u.max(0.0),
        }
    }

    /// `d theta/d u`.
    fn slope(&self, scale: Option<f64>, u: f64) -> f64 {
        match scale {
            None => u.exp(),
            Some(s) => s,
        }
    }

    /// `u + step`, the step limited (a factor of e^2 on the log scale, twice the value
    /// or 2 on the linear one) and projected on `u >= 0` on the linear scale.
    fn advance(&self, u: &[f64], step: &[f64]) -> Vec<f64> {
        u.iter()
            .zip(step)
            .zip(&self.scales)
            .map(|((ui, s), sc)| match sc {
                None => ui + s.clamp(-2.0, 2.0),
                Some(_) => {
                    let lim = 2.0 * ui.abs().max(1.0);
                    (ui + s.clamp(-lim, lim)).max(0.0)
                }
            })
            .collect()
    }

    /// Columns `d (model force)/d u`, at the masked samples.
    fn jacobian(&self, m: &Model, u: &[f64]) -> Vec<Vec<f64>> {
        // only the sensitivities the fitted parameters need, each once
        let mut base: Vec<BaseParam> = Vec::new();
        for b in self.params.iter().flat_map(|p| p.columns()) {
            if !base.contains(b) {
                base.push(*b);
            }
        }
        let sens = self.rec.base_sensitivities(m, &base);
        let col = |b: &BaseParam| &sens.columns[base.iter().position(|x| x == b).unwrap()];
        let mut out = Vec::with_capacity(self.params.len());
        for ((p, sc), &ui) in self.params.iter().zip(&self.scales).zip(u) {
            let d = self.slope(*sc, ui);
            let mut c = match p.columns() {
                [] => self.rec.a.clone(),
                [first, rest @ ..] => rest.iter().fold(col(first).clone(), |mut acc, b| {
                    acc.iter_mut().zip(col(b)).for_each(|(a, x)| *a += x);
                    acc
                }),
            };
            for (x, &k) in c.iter_mut().zip(self.mask) {
                *x = if k { *x * d } else { 0.0 };
            }
            out.push(c);
        }
        out
    }

    fn wsse(r: &[f64], w: &[f64]) -> f64 {
        r.iter().zip(w).map(|(r, w)| w * r * r).sum()
    }

    /// `(J^T W J, J^T W r)`, every product summed over the samples in their order in
    /// one pass (the sums of one pass per product, with their rounding); the rows in
    /// two parts, each on its own thread (rayon), the same numbers.
    fn normal(j: &[Vec<f64>], w: &[f64], r: &[f64]) -> (DMatrix<f64>, DVector<f64>) {
        let q = j.len();
        let n = j
            .iter()
            .map(Vec::len)
            .fold(w.len().min(r.len()), usize::min);
        // rows 0..m hold about half of the products (row i: i + 2 of them)
        let total = q * (q + 3) / 2;
        let mut m = 0;
        let mut acc = 0;
        while m < q && 2 * (acc + m + 2) <= total {
            acc += m + 2;
            m += 1;
        }
        let ((b0, l0), (b1, l1)) = rayon::join(
            || Self::normal_rows(j, w, r, n, 0..m),
            || Self::normal_rows(j, w, r, n, m..q),
        );
        let (b, lower) = ([b0, b1].concat(), [l0, l1].concat());
        let mut a = DMatrix::zeros(q, q);
        let mut p = 0;
        for i in 0..q {
            for k in 0..=i {
                a[(i, k)] = lower[p];
                a[(k, i)] = lower[p];
                p += 1;
            }
        }
        (a, DVector::from_vec(b))
    }

    /// The sums of [`Problem::normal`] of the rows `rows` over the first `n` samples:
    /// `J^T W r` and the lower triangle, row by row.
    fn normal_rows(
        j: &[Vec<f64>],
        w: &[f64],
        r: &[f64],
        n: usize,
        rows: std::ops::Range<usize>,
    ) -> (Vec<f64>, Vec<f64>) {
        let first = rows.start * (rows.start + 1) / 2;
        let last = rows.end * (rows.end + 1) / 2;
        // (`-0.0`: the start of a float `Iterator::sum`)
        let mut b = vec![-0.0f64; rows.len()];
        let mut lower = vec![-0.0f64; last - first];
        for t in 0..n {
            let (wt, rt) = (w[t], r[t]);
            let mut p = 0;
            for (bi, i) in b.iter_mut().zip(rows.clone()) {
                let x = j[i][t];
                *bi += x * wt * rt;
                for col in &j[..=i] {
                    lower[p] += x * col[t] * wt;
                    p += 1;
                }
            }
        }
        (b, lower)
    }

    /// `J^T W J` of a run's model in the parameters themselves (not their logs),
    /// row-major.
    fn information(&self, run: &Run) -> Vec<f64> {
        let u = self.encode(&run.model);
        let j = self.jacobian(&run.model, &u);
        let jt: Vec<Vec<f64>> = j
            .iter()
            .zip(&u)
            .zip(&self.scales)
            .map(|((c, ui), sc)| {
                let d = self.slope(*sc, *ui);
                c.iter().map(|x| x / d).collect()
            })
            .collect();
        let (a, _) = Self::normal(&jt, &run.w, &run.r);
        a.transpose().as_slice().to_vec()
    }

    fn run(&mut self, start: &Model, max_iter: usize) -> Result<Option<Run>> {
        let Some(mut r) = self.residual(start)? else {
            return Ok(None);
        };
        let mut model = start.clone();
        let mut u = self.encode(&model);
        let (mut w, mut scale) = self.weights(&r);
        let mut lam = 1e-3;
        let mut iterations = 0;
        let mut small = 0;
        let mut converged = false;
        for _ in 0..max_iter {
            iterations += 1;
            let cost = Self::wsse(&r, &w);
            let j = self.jacobian(&model, &u);
            let (a, b) = Self::normal(&j, &w, &r);
            let trace = a.trace().max(1e-300);
            let mut accepted = None;
            for _ in 0..12 {
                let mut m = a.clone();
                for i in 0..m.nrows() {
                    m[(i, i)] += lam * a[(i, i)] + 1e-12 * trace;
                }
                let Some(step) = m.lu().solve(&b) else {
                    lam *= 10.0;
                    continue;
                };
                let u2 = self.advance(&u, step.as_slice());
                let m2 = self.decode(&model, &u2);
                if let Some(r2) = self.residual(&m2)? {
                    let c2 = Self::wsse(&r2, &w);
                    if c2 < cost {
                        accepted = Some((m2, u2, r2, c2));
                        break;
                    }
                }
                lam *= 5.0;
            }
            let Some((m2, u2, r2, c2)) = accepted else {
                break;
            };
            lam = (lam / 3.0).max(1e-9);
            let rel = (cost - c2) / cost.max(1e-300);
            let moved = u2
                .iter()
                .zip(&u)
                .fold(0.0f64, |a, (x, y)| a.max((x - y).abs()));
            model = m2;
            u = u2;
            r = r2;
            (w, scale) = self.weights(&r);
            // converged: the sum of squares or the parameters (1e-5 of a log unit or of
            // a linear scale) stop moving, twice in a row
            small = if rel < self.opts.tol || moved < 1e-5 {
                small + 1
            } else {
                0
            };
            if small >= 2 {
                converged = true;
                break;
            }
        }
        let cost = Self::wsse(&r, &w);
        Ok(Some(Run {
            model,
            r,
            w,
            cost,
            scale,
            iterations,
            converged,
        }))
    }
}

/// Fit the base parameters `names` of a model to a record from several starts.
///
/// Every start is scored by its residual's sum of squares; the `scouts` best are
/// followed `scout_iter` iterations, and the `keep` best of those to convergence (a
/// scout that converged as it went stays as it is), by Levenberg-Marquardt on the
/// IGG-weighted residual (weights and scale renewed each iteration) and the one with
/// the smallest loss at a common scale wins. The parameters not named keep each
/// start's values.
///
/// # Errors
/// `mask` not of the record's length, no start, no parameter, an unknown name, or no
/// start with a finite residual.
pub fn fit_base(
    rec: &Record,
    starts: &[Model],
    mask: &[bool],
    names: &[String],
    opts: &BaseFitOptions,
) -> Result<BaseFit> {
    if mask.len() != rec.len() {
        return Err(Error::input(
            "mask",
            format!("has {} samples, the record {}", mask.len(), rec.len()),
        ));
    }
    if starts.is_empty() {
        return Err(Error::input("starts", "give at least one start model"));
    }
    let params = names
        .iter()
        .map(|n| FitParam::parse(n))
        .collect::<Result<Vec<_>>>()?;
    let vmax = rec.v.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let scales = params
        .iter()
        .map(|&p| scale_of(p, &starts[0], vmax))
        .collect();
    let mut pb = Problem {
        rec,
        mask,
        params: &params,
        scales,
        opts,
        evaluations: 0,
    };
    // the starts ranked by their residual's robust scale (the residuals in parallel)
    let first = rec.residuals(starts)?;
    pb.evaluations += starts.len();
    let mut ranked: Vec<(f64, usize)> = first
        .iter()
        .enumerate()
        .filter(|(_, r)| r.iter().all(|x| x.is_finite()))
        .map(|(k, r)| {
            let ss: f64 = r
                .iter()
                .zip(mask)
                .filter(|(_, &m)| m)
                .map(|(x, _)| x * x)
                .sum();
            (ss, k)
        })
        .collect();
    ranked.sort_by(|a, b| a.0.total_cmp(&b.0));
    // a few iterations from each of the most promising starts, then the best of those
    // to convergence: a start's first residual says little of where it leads
    let mut scouts: Vec<(usize, Run)> = Vec::new();
    for &(_, k) in ranked.iter().take(opts.scouts.max(opts.keep).max(1)) {
        if let Some(run) = pb.run(&starts[k], opts.scout_iter)? {
            scouts.push((k, run));
        }
    }
    let rank = |runs: Vec<(usize, Run)>| -> Vec<(f64, usize, Run)> {
        let smin = runs
            .iter()
            .map(|(_, r)| r.scale)
            .fold(f64::INFINITY, f64::min);
        let mut out: Vec<(f64, usize, Run)> = runs
            .into_iter()
            .map(|(k, r)| {
                let c =
                    r.r.iter()
                        .zip(mask)
                        .filter(|(_, &m)| m)
                        .map(|(x, _)| loss(&opts.weighting, x / smin))
                        .sum();
                (c, k, r)
            })
            .collect();
        out.sort_by(|a, b| a.0.total_cmp(&b.0));
        out
    };
    let mut runs: Vec<(usize, Run)> = Vec::new();
    for (_, k, scout) in rank(scouts).into_iter().take(opts.keep.max(1)) {
        if scout.converged {
            runs.push((k, scout));
        } else if let Some(mut run) = pb.run(&scout.model, opts.max_iter)? {
            run.iterations += scout.iterations;
            runs.push((k, run));
        }
    }
    let (criterion, start, best) = rank(runs).into_iter().next().ok_or_else(|| {
        Error::Data(
            "the model's residual is not finite at any start: check the recording's \
             units and the force constant"
                .into(),
        )
    })?;
    let values: Vec<f64> = params.iter().map(|p| p.get(&best.model)).collect();
    let information = if opts.information {
        pb.information(&best)
    } else {
        Vec::new()
    };
    Ok(BaseFit {
        values,
        cost: best.cost,
        scale: best.scale,
        criterion,
        weights: best.w.clone(),
        information,
        start,
        iterations: best.iterations,
        evaluations: pb.evaluations,
        model: best.model,
    })
}

#[cfg(test)]
mod tests {
    use super::Problem;

    /// The normal equations, rows in two parts on two threads, against each product
    /// summed on its own over the samples in their order: the same numbers.
    #[test]
    fn normal_in_two_parts_as_each_product_alone() {
        let n = 1000;
        let wave = |a: f64, k: usize| (a * k as f64).sin() + 0.1 * a;
        for q in 1..8 {
            let j: Vec<Vec<f64>> = (0..q)
                .map(|c| (0..n).map(|k| wave(0.37 + c as f64, k)).collect())
                .collect();
            let w: Vec<f64> = (0..n).map(|k| 1.0 + wave(0.05, k).abs()).collect();
            let r: Vec<f64> = (0..n).map(|k| wave(1.9, k)).collect();
            let (a, b) = Problem::normal(&j, &w, &r);
            for i in 0..q {
                let bi: f64 = (0..n).map(|t| j[i][t] * w[t] * r[t]).sum();
                assert_eq!(b[i].to_bits(), bi.to_bits());
                for k in 0..=i {
                    let s: f64 = (0..n).map(|t| j[i][t] * j[k][t] * w[t]).sum();
                    assert_eq!(a[(i, k)].to_bits(), s.to_bits());
                    assert_eq!(a[(k, i)].to_bits(), s.to_bits());
                }
            }
        }
    }
}
