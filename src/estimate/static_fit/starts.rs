//! Start values that gross errors do not pull away: a Huber grid over `ln vs` and a
//! high-breakdown least-trimmed-squares grid (the first stage of an MM-estimate).

use super::super::nelder_mead::NmOptions;
use super::super::robust::Weighting;
use super::varpro::{fill_phi, vp_minimize, Normal, Sep};

/// Median of a scratch buffer (reordered; NaN-free input).
pub(super) fn median_mut(b: &mut [f64]) -> f64 {
    let n = b.len();
    let (lo, m, _) = b.select_nth_unstable_by(n / 2, |x, y| x.total_cmp(y));
    let m = *m;
    if n % 2 == 1 {
        m
    } else {
        0.5 * (m + lo.iter().copied().fold(f64::NEG_INFINITY, f64::max))
    }
}

/// Nodes of the start grid over `ln vs`: from half the slowest to twice the fastest
/// speed.
pub(super) fn grid_nodes(a: &[f64], count: usize) -> Vec<f64> {
    let amin = a.iter().copied().fold(f64::INFINITY, f64::min);
    let amax = a.iter().copied().fold(0.0, f64::max);
    let (lo, hi) = ((amin * 0.5).ln(), (amax * 2.0).ln());
    (0..count)
        .map(|k| (lo + (hi - lo) * k as f64 / (count - 1) as f64).exp())
        .collect()
}

/// Number of `ln vs` nodes of the start grids.
pub(super) const GRID_NODES: usize = 17;

/// Start values `(fc, fs, sigma2, vs)` from the `ln vs` grid (Huber).
///
/// At each node a few Huber IRLS steps of the linear fit, scored by the median
/// absolute residual.
pub(super) fn start_values_huber(sep: &mut Sep) -> Option<[f64; 4]> {
    let n = sep.a.len();
    let huber = Weighting::huber();
    let mut w = vec![1.0; n];
    let mut e = vec![0.0; n];
    let mut buf = vec![0.0; n];
    let mut best: Option<(f64, [f64; 4])> = None;
    let fscale = sep.fc_min * 1e9;
    for vs in grid_nodes(sep.a, GRID_NODES) {
        fill_phi(sep.a, vs, &mut sep.phi);
        w.iter_mut().for_each(|v| *v = 1.0);
        let mut score = f64::INFINITY;
        let mut p = [f64::NAN; 4];
        for it in 0..4 {
            p = sep.params(&sep.normal(&w).solve_nonneg(), vs);
            let d = p[1] - p[0];
            for (((ei, &phi), &a), &y) in e.iter_mut().zip(&sep.phi).zip(sep.a).zip(sep.y) {
                *ei = y - (p[0] + d * phi + p[2] * a);
            }
            buf.iter_mut().zip(&e).for_each(|(b, x)| *b = *x);
            let med = median_mut(&mut buf);
            buf.iter_mut()
                .zip(&e)
                .for_each(|(b, x)| *b = (x - med).abs());
            let s = (1.4826 * median_mut(&mut buf)).max(1e-12 * fscale);
            if it == 3 {
                buf.iter_mut().zip(&e).for_each(|(b, x)| *b = x.abs());
                score = median_mut(&mut buf);
                break;
            }
            for (wi, ei) in w.iter_mut().zip(&e) {
                *wi = huber.weight(ei / s);
            }
        }
        if score.is_finite() && best.is_none_or(|(b, _)| score < b) {
            best = Some((score, p));
        }
    }
    best.map(|b| b.1)
}

/// Elemental subsets (three distinct indices below `n`) from a fixed-seed generator,
/// so that fits are reproducible: one point from each third of the speed range (by
/// rank), so that the three rows determine the level at low speed, the Coulomb level
/// and the viscous slope.
pub(super) fn elemental_seeds(a: &[f64], count: usize) -> Vec<[usize; 3]> {
    let n = a.len();
    let by_speed = by_speed(a);
    let mut rng = SplitMix64(0x2545_F491_4F6C_DD1D);
    let (t1, t2) = (n / 3, (2 * n) / 3);
    let mut out = Vec::with_capacity(count);
    if t1 == 0 || t2 == t1 {
        return out;
    }
    while out.len() < count {
        out.push([
            by_speed[rng.below(t1)],
            by_speed[t1 + rng.below(t2 - t1)],
            by_speed[t2 + rng.below(n - t2)],
        ]);
    }
    out
}

/// Indices of `a` in order of speed (a stable sort: equal speeds in input order).
fn by_speed(a: &[f64]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..a.len()).collect();
    order.sort_by(|&i, &j| a[i].total_cmp(&a[j]));
    order
}

/// SplitMix64 (Steele, Lea and Flood 2014): a small fixed-seed generator, so that the
/// random choices of the starts are the same in every run and in the NumPy twin.
struct SplitMix64(u64);

impl SplitMix64 {
    /// An index below `m` (0 when `m` is 0).
    fn below(&mut self, m: usize) -> usize {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) % m.max(1) as u64) as usize
    }
}

/// A subsample of `m < n` of the `n` points, spread over the speed range and the same
/// in every run: the points in order of speed cut into `m` runs of nearly equal length
/// (`floor(j n/m)` up to `floor((j+1) n/m)`), one point drawn from each by a fixed-seed
/// generator (not every k-th point, which a pattern in the data, such as a disturbance
/// every tenth run, could alias). Returned in input order.
pub(super) fn subsample(a: &[f64], m: usize) -> Vec<usize> {
    let n = a.len();
    if m >= n {
        return (0..n).collect();
    }
    let by_speed = by_speed(a);
    let mut rng = SplitMix64(0x5DEE_CE66_D1CE_5EED);
    let cut = |j: usize| ((j as u128 * n as u128) / m as u128) as usize;
    let mut out: Vec<usize> = (0..m)
        .map(|j| {
            let lo = cut(j);
            by_speed[lo + rng.below(cut(j + 1) - lo)]
        })
        .collect();
    out.sort_unstable();
    out
}

/// Least-trimmed-squares work at one `ln vs` node (the `phi` of the node in `sep`).
pub(super) struct Lts {
    h: usize,
    r2: Vec<f64>,
    order: Vec<usize>,
}

impl Lts {
    /// Fit on the points `sub`.
    pub(super) fn fit(sep: &Sep, sub: &[usize], vs: f64) -> [f64; 4] {
        let mut ne = Normal::default();
        for &i in sub {
            ne.add(sep.phi[i], sep.a[i], sep.y[i] - sep.fc_min, 1.0);
        }
        sep.params(&ne.solve_nonneg(), vs)
    }

    /// One concentration step (Rousseeuw and Van Driessen 2006): the trimmed sum of
    /// `p` (the `h` smallest squared residuals) and the fit on those `h` points, whose
    /// trimmed sum is no larger.
    pub(super) fn cstep(&mut self, sep: &Sep, p: &[f64; 4]) -> (f64, [f64; 4]) {
        let d = p[1] - p[0];
        for i in 0..sep.a.len() {
            let e = sep.y[i] - (p[0] + d * sep.phi[i] + p[2] * sep.a[i]);
            self.r2[i] = e * e;
        }
        let r2 = &self.r2;
        let h = self.h;
        if h < self.order.len() {
            self.order
                .select_nth_unstable_by(h, |&i, &j| r2[i].total_cmp(&r2[j]));
        }
        let sum = self.order[..h].iter().map(|&i| r2[i]).sum();
        (sum, Lts::fit(sep, &self.order[..h], p[3]))
    }

    /// Concentration steps from `p` until the trimmed sum stops decreasing (at most
    /// `max_steps`); the best trimmed sum, its fit and its subset in `self.order[..h]`.
    pub(super) fn concentrate(
        &mut self,
        sep: &Sep,
        p: [f64; 4],
        max_steps: usize,
    ) -> (f64, [f64; 4]) {
        let (mut obj, mut next) = self.cstep(sep, &p);
        let mut cur = p;
        for _ in 1..max_steps {
            let (o, nx) = self.cstep(sep, &next);
            if o.is_nan() || o >= obj * (1.0 - 1e-12) {
                if o <= obj {
                    return (o, next);
                }
                // the last step did not improve: restore the subset of `cur`
                self.cstep(sep, &cur);
                return (obj, cur);
            }
            cur = next;
            obj = o;
            next = nx;
        }
        (obj, cur)
    }
}

/// Start values `(fc, fs, sigma2, vs)` from the `ln vs` grid (least trimmed squares).
///
/// At each node the curve is linear in `(fc, fs, sigma2)`; a least-trimmed-squares
/// fit there (on about half the points, [`lts_h`]) resists gross errors also at the ends of
/// the speed range, where a single point has high leverage on `sigma2` and `fc` and
/// a monotone M-estimate (Huber) follows it. The nodes with the smallest trimmed sums
/// give the candidates (best first) that [`refine_lts`] finishes: the high-breakdown
/// first stage of an MM-estimate (Yohai 1987).
///
/// The nodes are visited in order of speed; at each, concentration steps start from
/// the plain fit, from the best subsets of the previous node and of all nodes so far,
/// and from a few fresh elemental (three-point) subsets, so that a good subset found
/// at one node is carried to its neighbours and the elemental subsets are spread over
/// the grid instead of being repeated at every node.
pub(super) fn start_values_lts(sep: &mut Sep, h: usize) -> Vec<[f64; 4]> {
    let n = sep.a.len();
    const SEEDS_PER_NODE: usize = 36;
    let nodes = grid_nodes(sep.a, GRID_NODES);
    let seeds = elemental_seeds(sep.a, SEEDS_PER_NODE * nodes.len());
    let mut lts = Lts {
        h,
        r2: vec![0.0; n],
        order: (0..n).collect(),
    };
    let all: Vec<usize> = (0..n).collect();
    let mut prev: Option<Vec<usize>> = None;
    let mut global: Option<(f64, [f64; 4], Vec<usize>)> = None;
    let mut node_subsets: Vec<Option<Vec<usize>>> = vec![None; nodes.len()];
    let mut found_at = 0;
    let mut candidates: Vec<(f64, [f64; 4], Vec<usize>)> = Vec::new();
    for (k, &vs) in nodes.iter().enumerate() {
        fill_phi(sep.a, vs, &mut sep.phi);
        let mut starts: Vec<[f64; 4]> = Vec::with_capacity(SEEDS_PER_NODE + 3);
        starts.push(Lts::fit(sep, &all, vs));
        if let Some(s) = &prev {
            starts.push(Lts::fit(sep, s, vs));
        }
        if let Some((_, _, s)) = &global {
            if prev.as_ref() != Some(s) {
                starts.push(Lts::fit(sep, s, vs));
            }
        }
        for sd in seeds.iter().skip(k * SEEDS_PER_NODE).take(SEEDS_PER_NODE) {
            starts.push(Lts::fit(sep, sd, vs));
        }
        // two concentration steps from each start, the best to convergence
        let mut node_best: Option<(f64, [f64; 4])> = None;
        for p0 in starts {
            let (obj, p) = lts.concentrate(sep, p0, 2);
            if obj.is_finite() && node_best.is_none_or(|b| obj < b.0) {
                node_best = Some((obj, p));
            }
        }
        let Some((_, p)) = node_best else {
            continue;
        };
        let (obj, p) = lts.concentrate(sep, p, 8);
        let mut sub = lts.order[..h].to_vec();
        sub.sort_unstable();
        node_subsets[k] = Some(sub.clone());
        prev = Some(sub.clone());
        if obj.is_finite() {
            candidates.push((obj, p, sub.clone()));
        }
        if global.as_ref().is_none_or(|g| obj < g.0) {
            global = Some((obj, p, sub));
            found_at = k;
        }
    }
    // the best subset carried back to the nodes visited before it was found (the
    // later ones started from it)
    let Some((_, _, best_sub)) = global.clone() else {
        return Vec::new();
    };
    for (k, &vs) in nodes.iter().enumerate().take(found_at) {
        if node_subsets[k].as_ref() == Some(&best_sub) {
            continue;
        }
        fill_phi(sep.a, vs, &mut sep.phi);
        let (obj, p) = lts.concentrate(sep, Lts::fit(sep, &best_sub, vs), 8);
        if obj.is_finite() {
            candidates.push((obj, p, best_sub.clone()));
        }
    }
    // the best few distinct subsets, best first
    candidates.sort_by(|x, y| x.0.total_cmp(&y.0));
    let mut out: Vec<[f64; 4]> = Vec::new();
    let mut seen: Vec<Vec<usize>> = Vec::new();
    for (_, p, sub) in candidates {
        if !seen.contains(&sub) {
            seen.push(sub);
            out.push(p);
            if out.len() == LTS_CANDIDATES {
                break;
            }
        }
    }
    out
}

/// Distinct grid subsets that [`refine_lts`] follows to a continuous `vs`.
const LTS_CANDIDATES: usize = 4;

/// Concentration steps with `vs` free: the `h` points of smallest residual at `p`,
/// the variable-projection fit on them (`vs` searched from `p`'s), until the subset
/// settles. The grid holds `vs` at a node, up to a factor 1.3 from the best; with a
/// hump of `fs - fc` tens of noise levels high, that misfit near `vs` can trade clean
/// points for gross errors, which the continuous step undoes. Returns the trimmed sum
/// of squares and the parameters.
pub(super) fn refine_lts(
    sep: &mut Sep,
    p0: [f64; 4],
    h: usize,
    nm: &NmOptions,
    floor: f64,
) -> (f64, [f64; 4]) {
    let n = sep.a.len();
    let mut p = p0;
    let mut w = vec![0.0; n];
    let mut order: Vec<usize> = (0..n).collect();
    let mut best = (f64::INFINITY, p0);
    for _ in 0..12 {
        let e = sep.residuals(&p);
        order.sort_by(|&i, &j| e[i].abs().total_cmp(&e[j].abs()));
        let obj: f64 = order[..h].iter().map(|&i| e[i] * e[i]).sum();
        if obj.is_nan() || obj >= best.0 * (1.0 - 1e-10) {
            break;
        }
        best = (obj, p);
        w.iter_mut().for_each(|x| *x = 0.0);
        for &i in &order[..h] {
            w[i] = 1.0;
        }
        let (pn, _) = vp_minimize(sep, &w, p[3].ln(), 0.05, nm, floor);
        if !pn.iter().all(|v| v.is_finite()) {
            break;
        }
        p = pn;
    }
    best
}

/// Subset sizes of the least-trimmed-squares starts: `(n + p + 1)/2` with `p = 3`
/// linear parameters (breakdown point about one half), three quarters of the points
/// (keeps the Stribeck hump when few points describe it) and two fifths (gross errors
/// scattered at random do not lie on one curve, so a smaller subset of clean points
/// still wins when a direction holds more than half gross errors). At least 5 points.
pub(super) fn lts_sizes(n: usize) -> [usize; 3] {
    let clamp = |h: usize| h.max(5).min(n);
    [
        clamp((n + 4) / 2),
        clamp((3 * n).div_ceil(4)),
        clamp((2 * n).div_ceil(5)),
    ]
}

/// Variance of a standard Gaussian truncated to `|z| <= k`.
pub(super) fn truncated_variance(k: f64) -> f64 {
    let phi = (-0.5 * k * k).exp() / (2.0 * std::f64::consts::PI).sqrt();
    1.0 - 2.0 * k * phi / libm::erf(k / std::f64::consts::SQRT_2)
}

/// Reweighting cut-off of [`lts_scale`], in units of the raw trimmed scale.
const LTS_REWEIGHT_CUT: f64 = 2.5;

/// High-breakdown residual scale of a least-trimmed-squares fit (the scale an
/// MM-estimate holds fixed in its M-step, Yohai 1987; reweighted as in Rousseeuw and
/// Van Driessen 2006). The raw scale is the root mean of the `h` smallest squared
/// residuals on `h - 4` degrees of freedom (the fit brought them down), made consistent
/// for Gaussian errors (the central fraction `h/n`); twice, the points within
/// [`LTS_REWEIGHT_CUT`] scales then give the scale on `kept - 4` degrees of freedom,
/// consistent for the truncation. Unlike the MAD of all residuals,
/// it does not grow with the share of gross errors as long as the `h` points are clean,
/// also when a direction holds half or more gross errors.
pub(super) fn lts_scale(e: &[f64], h: usize) -> f64 {
    let n = e.len();
    let h = h.clamp(1, n.max(1));
    let mut r2: Vec<f64> = e.iter().map(|x| x * x).filter(|x| !x.is_nan()).collect();
    if r2.len() < h {
        return f64::NAN;
    }
    r2.sort_by(|a, b| a.total_cmp(b));
    let frac = h as f64 / n as f64;
    // central quantile q of |z| with P(|z| <= q) = frac, by bisection on erf
    let (mut lo, mut hi) = (0.0f64, 10.0f64);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if libm::erf(mid / std::f64::consts::SQRT_2) < frac {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    // the fit had 4 parameters to bring the `h` residuals down
    let dof = (h as f64 - 4.0).max(1.0);
    let s = (r2[..h].iter().sum::<f64>() / dof / truncated_variance(0.5 * (lo + hi))).sqrt();
    reweight_scale(&r2, s)
}

/// The reweighting of [`lts_scale`] from the scale `s`: twice, the points within
/// [`LTS_REWEIGHT_CUT`] scales give the scale on `kept - 4` degrees of freedom,
/// consistent for the truncation. `r2`: the squared residuals in increasing order.
fn reweight_scale(r2: &[f64], s: f64) -> f64 {
    let mut s = s;
    if s == 0.0 {
        return s;
    }
    for _ in 0..2 {
        let cut2 = (LTS_REWEIGHT_CUT * s).powi(2);
        let kept: Vec<f64> = r2.iter().copied().take_while(|x| *x <= cut2).collect();
        if kept.len() <= 4 {
            break;
        }
        s = (kept.iter().sum::<f64>()
            / (kept.len() - 4) as f64
            / truncated_variance(LTS_REWEIGHT_CUT))
        .sqrt();
    }
    s
}

/// The scale of the residuals `e` of all points at a fit found on a subsample whose
/// clean points had the scale `s`: [`lts_scale`]'s reweighting started from `s`
/// rather than from the trimmed scale of a fixed share of the points (which, with
/// about half the points gross errors, a share of all points no longer separates).
pub(super) fn rescale(e: &[f64], s: f64) -> f64 {
    let mut r2: Vec<f64> = e.iter().map(|x| x * x).filter(|x| !x.is_nan()).collect();
    r2.sort_by(|a, b| a.total_cmp(b));
    reweight_scale(&r2, s)
}

/// Keep start values inside the model's domain (all positive, `fs > fc`).
pub(super) fn clamp_start(p: Option<[f64; 4]>, a: &[f64], fscale: f64) -> [f64; 4] {
    let amin = a.iter().copied().fold(f64::INFINITY, f64::min);
    let amax = a.iter().copied().fold(0.0, f64::max);
    let mut p =
        p.filter(|p| p.iter().all(|v| v.is_finite()))
            .unwrap_or([fscale, 1.5 * fscale, 0.0, amax]);
    p[0] = p[0].max(1e-3 * fscale);
    p[1] = p[1].max(p[0] * 1.01 + 1e-6 * fscale);
    p[2] = p[2].max(1e-6 * fscale / amax.max(1e-300));
    p[3] = p[3].clamp(amin * 0.5, amax * 2.0);
    p
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Deterministic standard-normal-like residuals (inverse CDF on a grid).
    fn gaussian(n: usize, sd: f64) -> Vec<f64> {
        (0..n)
            .map(|k| {
                let p = (k as f64 + 0.5) / n as f64;
                // bisection on erf for the quantile
                let (mut lo, mut hi) = (-10.0f64, 10.0f64);
                for _ in 0..80 {
                    let m = 0.5 * (lo + hi);
                    if 0.5 * (1.0 + libm::erf(m / std::f64::consts::SQRT_2)) < p {
                        lo = m;
                    } else {
                        hi = m;
                    }
                }
                sd * 0.5 * (lo + hi)
            })
            .collect()
    }

    #[test]
    fn subsample_is_spread_over_the_speeds_and_reproducible() {
        // speeds in no particular order, two runs at each of 1500 speeds
        let n = 3000;
        let a: Vec<f64> = (0..n)
            .map(|k| 1e-3 * (1 + (k * 7919) % 1500) as f64)
            .collect();
        let m = 400;
        let sub = subsample(&a, m);
        assert_eq!(sub, subsample(&a, m));
        assert_eq!(sub.len(), m);
        assert!(sub.windows(2).all(|w| w[0] < w[1]), "input order, distinct");
        // one point from each run of the speed ranks
        let order = by_speed(&a);
        let mut rank = vec![0; n];
        for (r, &i) in order.iter().enumerate() {
            rank[i] = r;
        }
        let mut ranks: Vec<usize> = sub.iter().map(|&i| rank[i]).collect();
        ranks.sort_unstable();
        for (j, r) in ranks.iter().enumerate() {
            assert!(j * n / m <= *r && *r < (j + 1) * n / m, "{j} {r}");
        }
        // a pattern every tenth point (in speed order, the order of a sweep) is not
        // aliased: about a tenth of the subsample falls on it, as of the data
        let sweep: Vec<f64> = (0..n).map(|k| 1e-4 * (k + 1) as f64).collect();
        let on = subsample(&sweep, m)
            .iter()
            .filter(|&&i| i % 10 == 0)
            .count();
        assert!((20..=60).contains(&on), "{on} of {m}");
        assert_eq!(subsample(&a[..50], 50), (0..50).collect::<Vec<_>>());
    }

    #[test]
    fn lts_scale_is_consistent_and_resists_half_gross_errors() {
        let clean = gaussian(400, 0.3);
        let h = lts_sizes(clean.len())[2];
        let s = lts_scale(&clean, h);
        assert!((s / 0.3 - 1.0).abs() < 0.05, "{s}");
        // as many gross errors as clean points, all on one side
        let mut mixed = gaussian(200, 0.3);
        mixed.extend((0..200).map(|k| 5.0 + 0.1 * k as f64));
        let s = lts_scale(&mixed, lts_sizes(mixed.len())[2]);
        assert!((s / 0.3 - 1.0).abs() < 0.1, "{s}");
        let mad = crate::estimate::robust_scale(&mixed);
        assert!(mad > 10.0 * s, "{mad} {s}");
        assert!(lts_scale(&[0.0; 8], 5) == 0.0);
    }
}
