"""Robust friction identification, the two steps of the seed paper, on the Rust core.

1. :func:`fit_static`: Stribeck parameters ``(fc, fs, sigma2, vs)`` of each direction from
   steady-state points, which :func:`steady_state_points` extracts from a raw record of
   constant-velocity plateaus.
2. :func:`fit_dynamic`: the bristle parameters ``sigma0`` and ``sigma1`` from a
   closed-loop position record, the static sets held, by simulating the model's
   controller; with confidence intervals and a verdict on what the record determines.

Both are iteratively reweighted least squares (IGG weights by default; Huber, Tukey or
none) with Nelder-Mead inside, as in the paper, with standard errors at the optimum.
"""

from __future__ import annotations

import warnings
from typing import Any, Callable

import numpy as np

from . import units as U
from ._core import fit_dynamic_record, fit_static_points, plateaus
from ._fits import STATIC_NAMES, DirectionFit, DynamicFit, StaticFit, SteadyStatePoints
from ._native import _array
from .exceptions import ConvergenceWarning, DataError, IdentifiabilityWarning, InputError
from .io import Recording, read_recording
from .model import Model, ModelLike, _as_model

__all__ = [
    "DirectionFit",
    "DynamicFit",
    "StaticFit",
    "SteadyStatePoints",
    "fit_dynamic",
    "fit_static",
    "steady_state_points",
    "stribeck_determinacy",
]


def fit_static(v: Any, F: Any, *, weighting: str = "igg", max_iter: int = 20,
               scale_floor: float = 0.0, max_start_points: int = 400) -> StaticFit:
    """Robust Stribeck fit of steady-state points, per direction.

    Parameters
    ----------
    v : array_like
        Constant velocities [m/s]; zero speeds are ignored (and counted).
    F : array_like
        Steady-state forces [N] (negative for ``v < 0``).
    weighting : {"igg", "huber", "tukey", "none"}
        Robust weight function; ``"none"`` is plain least squares.
    max_iter : int
        IRLS iterations at most.
    scale_floor : float
        Lower bound of the residual scale [N] (e.g. the force resolution).
    max_start_points : int
        Most points of a direction on which the robust starts are searched. A
        direction with more points is fitted as least trimmed squares is for large
        samples (FAST-LTS): the starts on a subsample of this many points spread over
        the speeds (the same in every run), then the best two paths once more on all
        points. At least 5; ``sys.maxsize`` for the starts on every point.

    Returns
    -------
    StaticFit

    Raises
    ------
    DataError
        Fewer than 5 points in a direction, one direction only, only zero speeds.
    InputError
        NaN or inf, lengths differ, empty input.
    ParameterError
        ``scale_floor`` negative or not finite, ``max_start_points`` below 5.

    Examples
    --------
    >>> import numpy as np, lugre
    >>> m = lugre.Model.paper()
    >>> v = np.concatenate([np.geomspace(2e-4, 0.4, 24), -np.geomspace(2e-4, 0.4, 24)])
    >>> fit = lugre.fit_static(v, lugre.stribeck(v, m))
    >>> round(fit.positive.params["fs"], 3)
    60.2
    """
    r = fit_static_points(_array("v", v), _array("F", F), str(weighting),
                                int(max_iter), float(scale_floor), int(max_start_points))
    fit = StaticFit(
        positive=DirectionFit._from_core(r.positive),
        negative=DirectionFit._from_core(r.negative),
        weights=r.weights,
        rejected=list(r.rejected),
        n_zero_speed=int(r.n_zero_speed),
        weighting=r.weighting,
        notes=list(r.notes),
    )
    if not fit.converged:
        warnings.warn("static fit: IRLS reached its iteration limit before the weights "
                      "settled; check the rejected points", ConvergenceWarning, stacklevel=2)
    return fit


def steady_state_points(recording: Recording | str, force_constant: float | None = None, *,
                        columns: dict[str, str] | None = None, settle_fraction: float = 0.3,
                        velocity_tolerance: float = 0.02, chunks: int = 1,
                        min_samples: int = 20) -> SteadyStatePoints:
    """Find constant-velocity plateaus in a raw record, drop transients, average.

    Plateaus are runs of constant ``v_ref`` when the record has it, else runs of nearly
    constant velocity differentiated from ``x``. The first ``settle_fraction`` of each,
    and any part where the speed is still off by more than ``velocity_tolerance``
    (relative), is dropped; plateaus that never settle (creep below the Stribeck
    velocity) are reported in ``notes`` and skipped.

    Parameters
    ----------
    recording : Recording or path
        With ``t``, ``x`` and ``F`` or ``i`` (then ``force_constant`` is needed).
    force_constant : float, optional
        K_F [N/A] for a record of currents.
    columns : dict, optional
        Column mapping when ``recording`` is a path.
    settle_fraction, velocity_tolerance, chunks, min_samples
        See above; ``chunks > 1`` cuts each settled plateau into replicate points.
    """
    return _steady_state_points(plateaus, recording, force_constant, columns=columns,
                                settle_fraction=settle_fraction,
                                velocity_tolerance=velocity_tolerance, chunks=chunks,
                                min_samples=min_samples)


def _steady_state_points(plateaus: Callable[..., Any],
                         recording: Recording | str, force_constant: float | None, *,
                         columns: dict[str, str] | None, settle_fraction: float,
                         velocity_tolerance: float, chunks: int,
                         min_samples: int) -> SteadyStatePoints:
    """:func:`steady_state_points` around ``plateaus(t, x, force, v_ref, settle_fraction,
    velocity_tolerance, window, min_samples, chunks)``, the plateau detection (the core's
    binding, or the NumPy twin's in ``lugre.reference``; both results have the same
    attributes): the recording and its force, the result and its notes."""
    rec = recording if isinstance(recording, Recording) else read_recording(recording, columns)
    F = rec.force(force_constant)
    r = plateaus(rec.t, rec.x, np.ascontiguousarray(F, dtype=float),
                 None if rec.v_ref is None else rec.v_ref, float(settle_fraction),
                 float(velocity_tolerance), 0, int(min_samples), int(chunks))
    plateaus = [
        {"start": s, "end": e, "velocity": v, "first_used": f, "settled": ok}
        for s, e, v, f, ok in zip(r.segment_start, r.segment_end, r.segment_velocity,
                                  r.segment_first_used, r.segment_settled)
    ]
    notes = list(r.notes)
    if len(notes) > 12:
        notes = notes[:10] + [(f"... and {len(notes) - 10} more plateaus skipped for the same "
                              "kind of reason (see .plateaus)")]
    return SteadyStatePoints(v=r.v, F=r.F, F_std=r.F_std, plateaus=plateaus,
                             used=np.asarray(r.used, dtype=bool), notes=notes)


def _check_stick_slip(rec: Recording) -> None:
    """The record must move and stick: sigma0 and sigma1 act near zero velocity."""
    src = rec.source or "the recording"
    x = np.asarray(rec.x, float)
    travel = float(np.ptp(x))
    steps = np.abs(np.diff(x))
    resolution = float(steps[steps > 0].min()) if np.any(steps > 0) else 0.0
    if travel == 0.0 or travel < 10 * resolution:
        raise DataError(
            f"{src}: the axis does not move (position range {travel:.3g} {U.si('m')}): the "
            "dynamic fit needs a closed-loop record with motion that sticks and slips"
        )
    dt = float(np.median(np.diff(rec.t)))
    w = max(1, round(0.01 / dt))  # 10 ms windows
    n = (len(x) - 1) // w
    v = np.abs(x[w: (n + 1) * w: w] - x[: n * w: w]) / (w * dt)
    if n < 3 or not np.any(v <= 0.02 * v.max()):
        raise DataError(
            f"{src}: no stick phase: the speed never falls near zero (slowest 10 ms window "
            f"{v.min() if n else float('nan'):.3g} {U.si('m/s')} against "
            f"{v.max() if n else 0:.3g} {U.si('m/s')} "
            "peak). sigma0 and sigma1 act where the axis sticks: record a slow ramp or "
            "reversals through a soft position loop (stick-slip)"
        )


def _static_cov(static_fit: StaticFit) -> dict[str, tuple[np.ndarray, int]]:
    """Each direction's joint covariance of ``fc, fs, sigma2, vs`` (diagonal from the
    standard errors when the full one is unavailable) and its degrees of freedom."""
    out = {}
    for d in ("positive", "negative"):
        df = getattr(static_fit, d)
        C = np.asarray(df.cov, float)
        if not np.all(np.isfinite(C)):
            C = np.diag([df.std_err[k] ** 2 if np.isfinite(df.std_err[k]) else 0.0
                         for k in STATIC_NAMES])
        out[d] = (0.5 * (C + C.T), max(int(np.sum(np.asarray(df.weights) > 0)) - 4, 1))
    return out


def _static_draws(cov: dict[str, tuple[np.ndarray, int]], n: int,
                  rng: np.random.Generator) -> dict[str, np.ndarray]:
    """``n`` draws of each direction's static errors from its joint covariance, as a
    multivariate t on the fit's degrees of freedom (the covariance rests on an
    estimated residual scale): ``{direction: (n, 4) array}``."""
    out = {}
    for d, (C, dof) in cov.items():
        lam, U = np.linalg.eigh(C)
        root = U * np.sqrt(np.clip(lam, 0.0, None))
        z = rng.standard_normal((n, 4)) @ root.T
        out[d] = z * np.sqrt(dof / rng.chisquare(dof, size=n))[:, None]
    return out


def _carry_static(static_fit: StaticFit, m: Model, est: np.ndarray, lo: np.ndarray,
                  hi: np.ndarray, identifiable: list[bool], notes: list[str], n_draws: int,
                  refit: Any) -> tuple[np.ndarray, np.ndarray, list[bool], list[str]]:
    """The static step's uncertainty in the intervals of ``ln sigma0, ln sigma1``.

    Refits at static sets drawn from the static step's joint covariance (both
    directions at once, fixed-seed generator so a fit is reproducible), then, per
    parameter, two refits at the ends of the static step's joint 95 % confidence region
    (``delta^T C^-1 delta = p F(p, dof)``) along the direction that moves it most (the
    gradient from a least-squares regression of the draws' refits): the interval holds
    the estimate and every refit, widened by the record's own noise half-width. It so
    holds the parameter for every static set in that region (a projection interval),
    which a parameter that depends far from linearly on the static sets needs: a
    static error a few standard errors along that one direction (as likely as a
    marginal 95 % miss of one static parameter) is still inside."""
    from scipy.stats import f as f_dist

    names = ("sigma0", "sigma1")
    sd_noise = (np.log(hi) - np.log(lo)) / (2 * 1.96)
    cov = _static_cov(static_fit)
    draws = _static_draws(cov, n_draws, np.random.default_rng(20240517))
    dirs = tuple(cov)
    base = np.concatenate([[getattr(m, d)[k] for k in STATIC_NAMES] for d in dirs])
    labels = [f"{k} ({d})" for d in dirs for k in STATIC_NAMES]
    C_all = np.zeros((8, 8))
    for i, d in enumerate(dirs):
        C_all[4 * i:4 * i + 4, 4 * i:4 * i + 4] = cov[d][0]
    sd_static = np.sqrt(np.diag(C_all))
    n_free = int(np.sum(sd_static > 0))
    dof = min(c[1] for c in cov.values())

    def at(delta: np.ndarray) -> np.ndarray | None:
        sets = {}
        for i, d in enumerate(dirs):
            b = base[4 * i:4 * i + 4]
            p = np.maximum(b + delta[4 * i:4 * i + 4], 1e-6 * np.abs(b))
            p[1] = max(p[1], p[0])          # fs >= fc
            sets[d] = dict(zip(STATIC_NAMES, map(float, p)))
        try:
            rr = refit(m.with_friction(**sets))
        except DataError:
            return None
        y = np.log([rr.sigma0, rr.sigma1]) - np.log(est)
        return y if np.all(np.isfinite(y)) else None

    ys, xs = [], []
    for i in range(n_draws):
        delta = np.concatenate([draws[d][i] for d in dirs])
        y = at(delta)
        if y is not None:
            ys.append(y)
            xs.append(delta)
    if len(ys) < 0.9 * n_draws or n_free == 0:
        if n_free == 0:
            return lo, hi, identifiable, notes
        notes.append(f"only {len(ys)} of {n_draws} refits at static sets drawn from the "
                     "static step's covariance succeeded: the intervals do not carry the "
                     "static uncertainty and are reported unbounded")
        return (np.zeros(2), np.full(2, np.inf), [False, False], notes)
    Y, X = np.array(ys), np.array(xs)
    keep = sd_static > 0
    Xs = (X[:, keep] - X[:, keep].mean(axis=0)) / sd_static[keep]
    coef = np.zeros((8, 2))
    coef[keep] = np.linalg.lstsq(np.column_stack([np.ones(len(Y)), Xs]), Y,
                                 rcond=None)[0][1:]
    radius = float(np.sqrt(n_free * f_dist.ppf(0.95, n_free, dof)))
    ends: list[list[float]] = [[], []]
    for j in range(2):
        g = np.zeros(8)
        g[keep] = coef[keep, j] / sd_static[keep]
        gcg = float(g @ C_all @ g)
        if not gcg > 0:
            continue
        step = radius * (C_all @ g) / np.sqrt(gcg)
        for sgn in (1.0, -1.0):
            y = at(sgn * step)
            if y is not None:
                ends[j].append(float(y[j]))
    h = 1.96 * sd_noise
    low = np.array([min([0.0, *Y[:, j], *ends[j]]) for j in range(2)])
    high = np.array([max([0.0, *Y[:, j], *ends[j]]) for j in range(2)])
    lo = est * np.exp(low - h)
    hi = est * np.exp(high + h)
    rel = (hi - lo) / (2 * est)
    identifiable = list(identifiable)
    for j, k in enumerate(names):
        var_static = float(np.var(Y[:, j]))
        share = var_static / (var_static + sd_noise[j] ** 2)
        was = identifiable[j]
        notes = [n for n in notes if not n.startswith(f"{k} = ")]
        identifiable[j] = bool(identifiable[j] and rel[j] <= 0.25)
        big = sorted(range(8), key=lambda c: -abs(coef[c, j]))[:2]
        causes = " and ".join(f"{labels[c]} ({100 * np.expm1(abs(coef[c, j])):.2g} % per "
                              "standard deviation)" for c in big)
        text = (f"{k}: refits at {len(Y)} static sets drawn from the static step's joint "
                f"covariance give {est[j] * np.exp(Y[:, j].min()):.5g} to "
                f"{est[j] * np.exp(Y[:, j].max()):.5g}"
                + (f", at the ends of its 95 % confidence region along the direction that "
                   f"moves {k} most {' and '.join(f'{est[j] * np.exp(e):.5g}' for e in ends[j])}"
                   if ends[j] else "")
                + f"; with the record's noise the 95 % interval is [{lo[j]:.5g}, {hi[j]:.5g}]"
                f" (+-{100 * rel[j]:.0f} %), {100 * share:.0f} % of its variance from the "
                f"static parameters, above all {causes}")
        if was and not identifiable[j]:
            text += (f"; NOT determined: {k} acts where the axis breaks away, where the "
                     "static curve's hump fs - fc and its width vs set the force too, and "
                     f"this record cannot separate {k} from the static step's errors there "
                     f"(above all {' and '.join(labels[c] for c in big)}). Measure it "
                     "directly (a presliding record at standstill, lugre.presliding) or "
                     "tighten the static step where those parameters act (lugre "
                     "design-static)")
        notes.append(text)
    return lo, hi, identifiable, notes


def fit_dynamic(recording: Recording | str, model: ModelLike, *, weighting: str = "igg",
                c1: float = 1.0, c2: float = 0.0, sigma0_start: float | None = None,
                sigma1_start: float | None = None, grid: bool = True, max_iter: int = 20,
                scale_floor: float = 0.0, substeps: int = 1, integrator: str = "exact",
                columns: dict[str, str] | None = None,
                static_fit: StaticFit | None = None, static_draws: int = 39) -> DynamicFit:
    """Estimate sigma0 and sigma1 from a closed-loop record (seed paper, eq. 18).

    The model's controller is simulated on the record's ``x_ref`` with the static sets
    held; ``c1*sum(w*e^2) + c2*max|e|`` of the position error ``e`` is minimised over
    ``ln sigma0, ln sigma1`` by Nelder-Mead inside IRLS.

    Parameters
    ----------
    recording : Recording or path
        With ``t``, ``x`` (measured position) and ``x_ref``.
    model : Model, dict or path
        Axis, static friction sets and the ``pid`` controller that produced the record.
    weighting : {"igg", "huber", "tukey", "none"}
    c1, c2 : float
        Weights of the sum of squares and of the largest error (eq. 18).
    sigma0_start, sigma1_start : float, optional
        Start values (default: the model's).
    grid : bool
        Evaluate a coarse grid first (protects against a poor start).
    max_iter, scale_floor, substeps, integrator
        IRLS iterations, lower bound of the residual scale [m] (e.g. the encoder
        resolution), and simulation settings.
    columns : dict, optional
        Column mapping when ``recording`` is a path.
    static_fit : StaticFit, optional
        The static step whose sets the model holds. Its uncertainty is carried into the
        intervals of sigma0 and sigma1 by refits at static sets drawn from its joint
        covariance (per direction, a multivariate t on the static fit's degrees of
        freedom) and at the two ends of its joint 95 % confidence region along the
        direction that moves each parameter most: the interval holds every refit,
        widened by the record's own noise interval, so it holds the parameter for every
        static set in that region. No linearisation is used: on the paper's axis the
        stick-slip estimate of sigma1 depends far from linearly on the break-away
        parameters (fs - fc, vs). A presliding record (:mod:`lugre.presliding`)
        determines sigma1 directly.
    static_draws : int
        Static sets drawn when ``static_fit`` is given (at least 5; each is one refit,
        plus four at the ends of the confidence region; the direction to those ends is
        regressed on the draws' refits, 8 static parameters, so fewer than about 20
        draws leave it rough).

    Warns
    -----
    IdentifiabilityWarning
        A parameter is not determined by the record (its notes say what would).
    """
    def core(mm: Model, rec: Recording, s0: float | None, s1: float | None,
             use_grid: bool) -> Any:
        return fit_dynamic_record(
            mm._core_model(), rec.t, rec.x_ref, rec.x, str(weighting), float(c1),
            float(c2), s0, s1, use_grid, int(max_iter), float(scale_floor), int(substeps),
            str(integrator))

    return _dynamic_fit(core, recording, model, sigma0_start=sigma0_start,
                        sigma1_start=sigma1_start, grid=grid, columns=columns,
                        static_fit=static_fit, static_draws=static_draws)


def _dynamic_fit(record_fit: Callable[..., Any], recording: Recording | str,
                 model: ModelLike, *, sigma0_start: float | None,
                 sigma1_start: float | None, grid: bool, columns: dict[str, str] | None,
                 static_fit: StaticFit | None, static_draws: int) -> DynamicFit:
    """:func:`fit_dynamic` around ``record_fit(model, recording, sigma0_start,
    sigma1_start, grid)``, the fit of one record (the core's binding, or the NumPy twin's
    in ``lugre.reference``; both results have the same attributes): input checks, the
    static step's uncertainty, the result, its warnings."""
    m = _as_model(model)
    rec = recording if isinstance(recording, Recording) else read_recording(recording, columns)
    if rec.x_ref is None:
        raise InputError.at("x_ref", f"{rec.source or 'the recording'} has no x_ref column: "
                            "the dynamic fit simulates the closed loop on the reference")
    if static_fit is not None and not (isinstance(static_draws, (int, np.integer))
                                       and static_draws >= 5):
        raise InputError.at("static_draws", f"is {static_draws!r}: give a whole number of at "
                            "least 5")

    def run(mm: Model, s0: float | None, s1: float | None, use_grid: bool) -> Any:
        return record_fit(mm, rec, s0, s1, use_grid)

    with U.axis(m.kind):
        _check_stick_slip(rec)
    r = run(m, sigma0_start, sigma1_start, bool(grid))
    names = ("sigma0", "sigma1")
    est = np.array([r.sigma0, r.sigma1], dtype=float)
    lo, hi = np.asarray(r.ci_low, float), np.asarray(r.ci_high, float)
    notes = list(r.notes)
    identifiable = [bool(b) for b in r.identifiable]
    if static_fit is not None:
        lo, hi, identifiable, notes = _carry_static(
            static_fit, m, est, lo, hi, identifiable, notes, int(static_draws),
            lambda mm: run(mm, float(est[0]), float(est[1]), False))
    # an interval that cannot be computed (an estimate at the bound, a refit that
    # failed) says nothing: report it as unbounded and the parameter as undetermined
    for j, k in enumerate(names):
        if not (np.isfinite(lo[j]) and np.isfinite(hi[j])):
            lo, hi = np.array(lo, float), np.array(hi, float)
            lo[j], hi[j] = 0.0, np.inf
            if identifiable[j]:
                notes.append(f"{k}: its interval cannot be computed (estimate {est[j]:.4g} "
                             "at or near a bound): NOT determined by this record")
            identifiable[j] = False
    fit = DynamicFit(
        sigma0=float(est[0]), sigma1=float(est[1]),
        std_err=dict(zip(names, map(float, r.std_err))),
        ci95={k: (float(a), float(b)) for k, a, b in zip(names, lo, hi)},
        identifiable=dict(zip(names, identifiable)),
        correlation=float(r.correlation), notes=notes,
        residuals=r.residuals, weights=r.weights, rms_error=float(r.rms_error),
        max_error=float(r.max_error), iterations=int(r.iterations),
        evaluations=int(r.evaluations), converged=bool(r.converged),
        model=m.with_friction(sigma0=float(est[0]), sigma1=float(est[1])),
    )
    for k in names:
        if not fit.identifiable[k]:
            lo_k, hi_k = fit.ci95[k]
            warnings.warn(f"{k} is not determined by this record (95 % interval "
                          f"[{lo_k:.4g}, {hi_k:.4g}]); the fit's notes say which experiment "
                          "would determine it", IdentifiabilityWarning, stacklevel=3)
    if not fit.converged:
        warnings.warn("dynamic fit: IRLS reached its iteration limit", ConvergenceWarning,
                      stacklevel=3)
    return fit


def stribeck_determinacy(recording: Recording, model: ModelLike) -> list[str]:
    """What a record cannot tell about the Stribeck parameters of a fitted model.

    The hump ``fs - fc`` and its width ``vs`` act only below a few ``vs``: a record
    whose motion in a direction stays faster (or crosses the slow range in a few
    samples, as at a reversal) cannot determine them, whatever a fit returns. Per
    direction: when the fit has no hump (``fs`` within 1 % of ``fc``), ``fs`` and ``vs``
    are named undetermined (any ``vs`` fits equally); otherwise they are when fewer than
    200 samples (or 2 % of the direction's moving samples) move slower than ``2 vs``.

    Parameters
    ----------
    recording : Recording
        The record the model was fitted to (``v``, or ``x`` differentiated).
    model : Model, dict or path
        The fitted model.

    Returns
    -------
    list of str
        One statement per undetermined direction, with the experiment that would
        determine it; empty when the record covers the slow range.
    """
    m = _as_model(model)
    with U.axis(m.kind):
        return _stribeck_notes(recording, m)


def _stribeck_notes(recording: Recording, m: Model) -> list[str]:
    """:func:`stribeck_determinacy` in the units of ``m``'s axis."""
    v = recording.v if recording.v is not None else np.gradient(recording.x, recording.t)
    v = np.asarray(v, float)
    top = float(np.max(np.abs(v))) if v.size else 0.0
    out = []
    f_u, v_u = U.si("N"), U.si("m/s")
    for d, sign, tag in (("positive", 1.0, "v > 0"), ("negative", -1.0, "v < 0")):
        p = getattr(m, d)
        moving = sign * v > 1e-3 * top
        n_mov = int(moving.sum())
        if n_mov == 0:
            out.append(f"{tag}: the record never moves this way, so fc, fs, sigma2 and vs of "
                       "this direction are not determined; record motion in this direction")
            continue
        a = np.abs(v[moving])
        slow = 0.05 * top
        share_slow = float(np.mean(a < slow))
        what = (f"constant-velocity runs in this direction from about {slow / 50:.2g} to "
                f"{slow:.2g} {v_u} (lugre fit-static; lugre design-static proposes the "
                "speeds)")
        if p["fs"] <= 1.01 * p["fc"]:
            out.append(f"{tag}: the fit found no Stribeck hump (fs = {p['fs']:.4g} {f_u}, "
                       f"fc = {p['fc']:.4g} {f_u}), so fs and vs (= {p['vs']:.3g} {v_u}, any "
                       "value fits) "
                       f"are NOT determined by this record: {100 * share_slow:.1f} % of its "
                       f"moving samples are slower than {slow:.2g} {v_u} (5 % of the top "
                       f"speed). Would determine them: {what}")
            continue
        n_hump = int(np.sum(a < 2 * p["vs"]))
        if n_hump < 200 or n_hump < 0.02 * n_mov:
            out.append(f"{tag}: fs and vs rest on {n_hump} samples slower than 2 vs = "
                       f"{2 * p['vs']:.3g} {v_u} ({100 * n_hump / n_mov:.1f} % of the moving "
                       f"ones): NOT determined by this record. Would determine them: {what}")
    return out
