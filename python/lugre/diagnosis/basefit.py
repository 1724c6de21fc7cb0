"""The base model fitted where the record puts it: mass and per-direction LuGre
friction by robust Levenberg-Marquardt on the inverse-dynamics residual (the kernel's
``fit_base``), from starts that cover the Stribeck hump and the bristle stiffness, and
each parameter's profile (the fit with it moved and the rest refitted) for its interval
and whether the record determines it."""

from __future__ import annotations

import itertools
import math
import warnings
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from .. import units as U
from ..model import Model
from ..vocabulary import DRAG, SPRING
from . import residual as R
from .base import apply_base, get_base
from .golden import golden

__all__ = ["BaseFitResult", "base_names", "fit_base", "identify", "profile_all", "starts",
           "with_profiles"]

#: A profile that rises by less than this (chi-square, one parameter, 95 %) over a
#: factor of ten either way leaves the parameter not determined on that side.
CHI2_95 = 3.841

#: Factor a profile goes out to before it calls a side unbounded.
PROFILE_SPAN = 10.0

#: The linear start fitted where the axis slides faster than this share of its
#: largest speed (the static curve describes sliding, not sticking).
SLIDING = 0.05

#: Starts: hump ratios fs/fc, Stribeck speeds (shares of the largest speed) and
#: presliding displacements fs/sigma0 (shares of the stroke, at least a few counts).
RATIOS = (1.0, 1.6, 2.6)
#: ... and shares of the linear fit's Coulomb level (the rest of the mean sliding
#: friction given to the viscous term): the linear fit trades one for the other.
FC_SHARES = (1.0, 0.6, 0.35)

SIDES = ("positive", "negative")

#: A record is halved (every other sample) to see what its sampling does to the
#: parameters when it keeps at least this many samples.
MIN_HALF = 1000

#: The record is read again in the fitted model's band when it differs from the start's
#: by more than this factor.
BAND_CHANGE = 1.25

#: Most times the record is read again in a new band (each a fit from the grid).
BAND_READS = 3

#: Starts followed a few iterations before the best few are followed to the end.
SCOUTS = 16
VS_SHARES = (0.003, 0.01, 0.03, 0.1, 0.3)


@dataclass(frozen=True)
class BaseFitResult:
    """A base fit: the model, its parameters' intervals and what the record leaves open.

    ``profiles[name]`` holds ``value``, ``ci95`` ([lo, hi], None for an unbounded side),
    ``determined`` and ``how`` (``"wald"`` or ``"profile"``) for every fitted parameter
    (``positive.hump`` is ``fs - fc``).
    """

    model: Model
    names: tuple[str, ...]
    scale: float
    rms: float
    noise: float
    n_eff: float
    evaluations: int
    profiles: dict[str, dict[str, Any]] = field(default_factory=dict)
    diagnosis: Any = None
    #: ``J^T W J`` of the fit in the parameters themselves (for the intervals)
    information: Any = field(default=None, repr=False)
    #: effects fitted beside the base and left out of ``model`` (a joint's gravity,
    #: which the diagnosis names): said by the fit's report
    set_aside: tuple[dict[str, Any], ...] = ()

    @property
    def floor_ratio(self) -> float:
        """The residual's rms over the record's noise floor (1: nothing left to fit)."""
        return self.rms / self.noise if self.noise > 0 else math.inf

    def floor_words(self) -> tuple[str, bool]:
        """How far the fit is from the record's noise floor, in words, and whether that
        is far enough to warn."""
        with U.axis(self.model.kind):
            u = U.si("N")
            head = (f"{U.force_words()} residual {self.rms:.3g} {u} rms against a noise floor "
                    f"of {self.noise:.3g} {u} ({self.floor_ratio:.2g} times)")
        q = self.floor_ratio
        if q <= 1.5:
            return head + ": at the record's noise floor, nothing systematic is left", False
        if q <= 3.0:
            return (head + ": close to the noise floor; lugre diagnose says whether the "
                    "rest is physics the model leaves out"), False
        return (head + ": far from the noise floor, so the record holds something this "
                "model does not (cogging, a spring, an offset, a resonance, timing, ...): "
                "run lugre diagnose on this record with this model before relying on "
                "it"), True


def base_names(free_mass: bool) -> list[str]:
    """The fitted parameters: mass (when free), the four of each direction, sigma0 and
    sigma1."""
    out = ["mass"] if free_mass else []
    for d in ("positive", "negative"):
        out += [f"{d}.fc", f"{d}.hump", f"{d}.sigma2", f"{d}.vs"]
    return out + ["sigma0", "sigma1"]


def starts(model: Model, sig: R.Signals) -> list[Model]:
    """Start models around ``model`` (its mass and effects kept): the model itself
    first, then every hump ratio, Stribeck speed, presliding displacement and
    Coulomb/viscous split of the grids."""
    vmax = float(np.max(np.abs(sig.v[sig.mask]))) or 1e-6
    xs = sig.x[sig.mask]
    stroke = float(np.ptp(xs)) or 1e-6
    q = max(float(sig.info.get("quantum", 0.0)), stroke * 1e-7)
    pre = np.geomspace(max(3 * q, stroke * 1e-5), max(stroke * 0.02, 6 * q), 4)
    speeds = np.abs(sig.v[sig.mask])
    sliding = speeds[speeds > SLIDING * vmax]
    vmean = float(np.mean(sliding)) if sliding.size else vmax
    out = [model]
    fr = model.friction
    levels = [{d: (float(fr[d]["fc"]) * k, float(fr[d]["sigma2"])
                   + (1 - k) * float(fr[d]["fc"]) / vmean) for d in SIDES} for k in FC_SHARES]
    # a direction whose linear fit went astray (no hump found, the slope taken up by
    # the Coulomb level) started from the other's levels
    levels += [{d: (float(fr[o]["fc"]), float(fr[o]["sigma2"])) for d in SIDES} for o in SIDES]
    for ratio, share, x0, lv in itertools.product(RATIOS, VS_SHARES, pre, levels):
        vals: dict[str, float] = {}
        for d in SIDES:
            vals[f"{d}.fc"], vals[f"{d}.sigma2"] = lv[d]
            vals[f"{d}.fs"] = lv[d][0] * ratio
            vals[f"{d}.vs"] = share * vmax
        vals["sigma0"] = max(vals["positive.fs"], vals["negative.fs"]) / x0
        vals["sigma1"] = 0.05 * math.sqrt(vals["sigma0"] * model.mass)
        out.append(apply_base(model, vals))
    return out


def _run(sig: R.Signals, start: list[Model], names: list[str], keep: int = 3,
         max_iter: int = 60, tol: float = 1e-6, information: bool = True
         ) -> tuple[Model, dict[str, Any]]:
    """The kernel's fit from ``start``: the best model and the kernel's dict (its
    ``information`` None unless asked; ``tol``: the relative fall of the weighted sum
    of squares below which a start stops, twice in a row)."""
    out = sig.kernel.fit_base(start, [bool(b) for b in sig.mask], names,
                              max_iter=max_iter, keep=keep, scouts=max(keep, SCOUTS),
                              tol=tol, information=information)
    return apply_base(start[out["start"]], out["values"]), out


class Polisher:
    """The base polished from a model (its other effects held): its residual's rms
    [N], the polished model and its residual. The rms is infinite where the kernel
    refuses the model, or where the polish moved the mass beyond ``mass_factor``
    either way (a base that sheds its mass to make room for an effect is no axis)."""

    def __init__(self, sig: R.Signals, names: list[str],
                 mass_factor: float | None = None) -> None:
        self.sig, self.names, self.mass_factor = sig, names, mass_factor

    def __call__(self, model: Model, max_iter: int) -> tuple[float, Model, np.ndarray]:
        refused = math.inf, model, np.full(len(self.sig), np.inf)
        try:
            best, _ = _run(self.sig, [model], self.names, keep=1, max_iter=max_iter,
                           information=False)
            f = self.mass_factor
            if f is not None and not 1.0 / f < best.mass / model.mass < f:
                return refused
            r = np.asarray(self.sig.kernel.residual(best))
        except (ValueError, ArithmeticError):  # (a model the kernel refuses)
            return refused
        used = r[self.sig.mask]
        rms = float(np.sqrt(np.mean(used * used)))
        return (rms if math.isfinite(rms) else math.inf), best, r


def _value(model: Model, name: str) -> float:
    if name.endswith(".hump"):
        d = name.split(".")[0]
        return get_base(model, f"{d}.fs") - get_base(model, f"{d}.fc")
    return get_base(model, name)


def _with(model: Model, name: str, value: float) -> Model:
    if name.endswith(".hump"):
        d = name.split(".")[0]
        return apply_base(model, {f"{d}.fs": get_base(model, f"{d}.fc") + value})
    if name.endswith(".fc"):
        d = name.split(".")[0]
        hump = _value(model, f"{d}.hump")
        return apply_base(model, {name: value, f"{d}.fs": value + hump})
    return apply_base(model, {name: value})


def fit_base(sig: R.Signals, model: Model, *, free_mass: bool, extra: list[Model] | None = None,
             profiles: bool = True, grid: bool = True,
             shift: dict[str, float] | None = None) -> BaseFitResult:
    """Fit the base of ``model`` to a prepared record from the start grid (and
    ``extra`` starts), then profile each parameter.

    Parameters
    ----------
    sig : Signals
        The prepared record (its kernel: the core's or the twin's).
    model : Model
        The levels and mass to start from (its effects are held).
    free_mass : bool
        Fit the mass too.
    extra : list of Model, optional
        Further starts (a model given by the user).
    profiles : bool, default True
        Work out each parameter's interval and whether the record determines it.
    grid : bool, default True
        Start from the grid around ``model``; else from ``model`` alone (a polish).
    shift : dict, optional
        Per parameter, how far it moves when the record is read at half its rate (the
        intervals are widened by it).

    Returns
    -------
    BaseFitResult
    """
    names = base_names(free_mass)
    first = starts(model, sig) if grid else [model]
    best, out = _run(sig, first + list(extra or []), names)
    r = np.asarray(sig.kernel.residual(best))
    nf = R.noise_floor(r, sig)
    used = r[sig.mask]
    res = BaseFitResult(model=best, names=tuple(names), scale=float(out["scale"]),
                        rms=float(np.sqrt(np.mean(used * used))), noise=float(nf["rms"]),
                        n_eff=float(nf["n_eff"]), evaluations=int(out["evaluations"]),
                        information=np.asarray(out["information"]))
    return with_profiles(sig, res, shift) if profiles else res


def with_profiles(sig: R.Signals, res: BaseFitResult,
                  shift: dict[str, float] | None = None) -> BaseFitResult:
    """``res`` with every parameter's interval and determinacy, and the simplest values
    where the record is silent (:func:`simplest`)."""
    res = replace(res, profiles=profile_all(sig, res, res.information, shift))
    return simplest(sig, res)


def simplest(sig: R.Signals, res: BaseFitResult) -> BaseFitResult:
    """Where the record leaves a parameter open, the simplest value it allows: a hump
    that the noise allows from zero to any size is zero (fs = fc; a break-away of ten
    times the Coulomb level on a handful of samples is no finding; a hump bounded above
    is kept, as the record put it), and a damping sigma1 it does not determine is held
    within the passivity bound. The others are refitted."""
    prof = dict(res.profiles)
    vals: dict[str, float] = {}
    held: list[str] = []
    for d in SIDES:
        p = prof.get(f"{d}.hump")
        ci = (p or {}).get("ci95") or [None, None]
        if p and not p["determined"] and p["value"] > 0 and ci[0] in (None, 0.0) and (
                ci[1] is None):
            vals[f"{d}.fs"] = get_base(res.model, f"{d}.fc")
            held += [f"{d}.hump", f"{d}.vs"]
    s1 = prof.get("sigma1")
    if s1 and not s1["determined"]:
        bound = _passive_sigma1(apply_base(res.model, vals))
        lo, hi = s1.get("ci95") or [None, None]
        if get_base(res.model, "sigma1") > bound and (lo is None or lo <= bound):
            # within the record's interval when it has one (a sigma1 of 955-1458 N s/m
            # held at half its bound, 524, left the fit at four times the noise floor)
            vals["sigma1"] = 0.5 * bound if hi is None else max(lo or 0.0, bound)
            held.append("sigma1")
    if not vals:
        return res
    names = [n for n in res.names if n not in held]
    fitted, _ = _run(sig, [apply_base(res.model, vals)], names, keep=1, max_iter=30)
    for n in res.names:
        prof[n] = {**prof[n], "value": _value(fitted, n)}
    for n in held:
        prof[n] = {**prof[n], "how": "held (simplest)", "determined": False}
    r = np.asarray(sig.kernel.residual(fitted))[sig.mask]
    return replace(res, model=fitted, profiles=prof, rms=float(np.sqrt(np.mean(r * r))))


def _passive_sigma1(m: Model) -> float:
    """The largest sigma1 that keeps both directions passive (Barabanov & Ortega 2000)."""
    out = math.inf
    for d in SIDES:
        st = m.friction[d]
        hump = float(st["fs"]) - float(st["fc"])
        if hump > 0:
            out = min(out, 4.0 * float(st["sigma2"]) * float(st["fc"]) / hump)
    return out


def _chi2(sig: R.Signals, model: Model, q0: float, cut: float, s2: float, ratio: float) -> float:
    r = np.asarray(sig.kernel.residual(model))[sig.mask]
    q = float(np.sum(np.minimum(r * r, cut)))
    return (q - q0) / s2 * ratio


def _covariance(info: np.ndarray) -> np.ndarray:
    """The inverse of the information, scaled to unit diagonal first; a direction the
    record does not inform (a near-singular information) gives its parameters an
    infinite variance, not the small one a pseudo-inverse would."""
    d = np.sqrt(np.clip(np.diag(info), 0.0, None))
    q = info.shape[0]
    out = np.full((q, q), np.inf)
    ok = d > 0
    if not ok.any():
        return out
    sub = info[np.ix_(ok, ok)] / np.outer(d[ok], d[ok])
    w, V = np.linalg.eigh(sub)
    inv_w = np.where(w > 1e-10 * max(float(w.max()), 1e-300), 1.0 / np.maximum(w, 1e-300),
                     np.inf)
    with np.errstate(invalid="ignore"):
        c = (V * inv_w) @ V.T
        # a parameter with a share in an uninformed direction gets an infinite variance
        var = (V ** 2) @ inv_w
    c[np.diag_indices_from(c)] = var
    out[np.ix_(ok, ok)] = c / np.outer(d[ok], d[ok])
    return out


def profile_all(sig: R.Signals, res: BaseFitResult, info: np.ndarray,
                shift: dict[str, float] | None = None) -> dict[str, dict[str, Any]]:
    """Intervals of every fitted parameter: from the information where it bounds the
    parameter to within 10 % (the profile is then quadratic), else from the profile,
    refitting the others at each point; each widened by ``shift[name]``, how far the
    parameter moves when the record is read at half its rate (a bias of the sampling
    that the noise does not show)."""
    shift = shift or {}
    names = list(res.names)
    best = res.model
    n_used = int(sig.mask.sum())
    ratio = min(1.0, res.n_eff / max(n_used, 1))
    s2 = res.scale ** 2
    cut = (2.5 * res.scale) ** 2
    r0 = np.asarray(sig.kernel.residual(best))[sig.mask]
    q0 = float(np.sum(np.minimum(r0 * r0, cut)))
    cov = _covariance(np.asarray(info, dtype=float)) * s2 / ratio
    out: dict[str, dict[str, Any]] = {}
    for k, name in enumerate(names):
        val = _value(best, name)
        se = math.sqrt(max(cov[k, k], 0.0))
        if name.endswith(".vs") and _value(best, name.replace(".vs", ".hump")) < 1e-3 * max(
                get_base(best, name.replace(".vs", ".fc")), 1e-12):
            out[name] = {"value": val, "ci95": None, "determined": False, "how": "no hump",
                         "se": math.nan}
            continue
        sh = abs(shift.get(name, 0.0))
        hw = 1.96 * se + sh
        if val > 0 and hw <= 0.1 * val:
            out[name] = {"value": val, "ci95": [val - hw, val + hw], "determined": True,
                         "how": "wald", "se": se, "sampling": sh}
            continue
        others = [n for n in names if n != name]
        ends: list[float | None] = []
        for sgn in (-1.0, 1.0):
            ends.append(_profile_side(sig, best, name, val, sgn, others,
                                      lambda m: _chi2(sig, m, q0, cut, s2, ratio)))
        lo, hi = ends
        lo = None if lo is None else max(lo - sh, 0.0)
        hi = None if hi is None else hi + sh
        det = lo is not None and hi is not None and (hi - lo) <= 0.4 * max(val, 1e-300)
        if val <= 0.0 and hi is not None:
            # at zero the width is read against the parameter's natural size
            det = hi <= ZERO_SPAN[0] * _zero_scale(sig, best, name)
        out[name] = {"value": val, "ci95": [lo, hi], "determined": det, "how": "profile",
                     "se": se, "sampling": sh}
    return out


#: Steps of a damping's profile up from zero, in its natural size
#: (:func:`_zero_scale`); the first is also the most a damping at zero may reach
#: within its interval and be called determined.
ZERO_SPAN = (0.05, 0.3, 1.0)


def _zero_scale(sig: R.Signals, best: Model, name: str) -> float:
    """The natural size of a damping the fit put at zero: for ``sigma1`` a twentieth of
    the bristles' critical damping against the mass, ``0.05*sqrt(sigma0*m)`` (as the
    grid of starts has it; the paper's axis: 79 N s/m for 31.6); for a viscous
    ``sigma2`` the Coulomb level over the record's largest speed. (Multiplicative steps never leave
    zero: a sigma1 of 0 read "determined, 0 to 0" and the diagnosis took it as such.)"""
    if name == "sigma1":
        return 0.05 * math.sqrt(max(get_base(best, "sigma0"), 0.0) * best.mass)
    vmax = float(np.max(np.abs(sig.v[sig.mask]))) or 1e-6
    return get_base(best, name.replace(".sigma2", ".fc")) / vmax


def _profile_side(sig: R.Signals, best: Model, name: str, val: float, sgn: float,
                  others: list[str], chi2: Any) -> float | None:
    """Where the profile on one side crosses the 95 % level (None: within the noise
    out to a factor of ten, or to zero for a hump)."""
    hump = name.endswith(".hump")
    fc = get_base(best, name.replace(".hump", ".fc")) if hump else 0.0
    if hump:  # additive steps: the hump may be zero
        steps = [0.05 * fc, 0.2 * fc, 1.0 * fc]
        pts = [val + sgn * s for s in steps]
    elif val <= 0.0 and sgn > 0:  # (a damping at zero: steps of its natural size)
        pts = [f * _zero_scale(sig, best, name) for f in ZERO_SPAN]
    else:
        pts = [val * PROFILE_SPAN ** (sgn * f) for f in (0.05, 0.3, 1.0)]
    prev_x, prev_c = val, 0.0
    for x in pts:
        if x <= 0:
            return 0.0 if hump or name.endswith(("sigma1", "sigma2")) else None
        m = _with(best, name, x)
        fitted, _ = _run(sig, [m], others, keep=1, max_iter=25)
        c = max(chi2(fitted), 0.0)
        if c >= CHI2_95:
            # linear in the chi-square's square root between the last two points
            a, b = math.sqrt(prev_c), math.sqrt(c)
            f = (math.sqrt(CHI2_95) - a) / (b - a) if b > a else 1.0
            return prev_x + f * (x - prev_x)
        prev_x, prev_c = x, c
    return None


def identify(recording: Any, *, mass: float | None = None, force_constant: float = 1.0,
             cutoff_hz: float | None = None, controller: dict[str, Any] | None = None,
             backend: Any = "core", profiles: bool = True) -> BaseFitResult:
    """Identify an axis's base model from a recording: the inverse-dynamics levels
    (robust linear least squares) as the start of :func:`fit_base`.

    Parameters
    ----------
    recording : Recording or path
        With motion in both directions.
    mass : float, optional
        Known mass [kg]; fitted otherwise.
    force_constant : float, default 1.0
        K_F [N/A].
    cutoff_hz : float, optional
        Low-pass cut-off (default ``fs/25``).
    controller : dict, optional
        Controller section to put in the model.
    backend : "core" or module, default "core"
        The kernels: the compiled core, or a kernels module such as
        :mod:`lugre.reference.kernels` (the NumPy twin; slower, for checking).
    profiles : bool, default True
        Intervals and determinacy of every parameter.

    Returns
    -------
    BaseFitResult
    """
    from ..exceptions import PassivityWarning
    from .evaluation import as_recording

    rec = as_recording(recording)
    with warnings.catch_warnings(), U.axis(rec.meta.get("axis_kind", "linear")):
        warnings.simplefilter("ignore", PassivityWarning)  # (the starts and trial models)
        res = _identify(rec, mass, force_constant, cutoff_hz, controller,
                        backend, profiles)
    return _passive(res)


def _passive(res: BaseFitResult) -> BaseFitResult:
    """The fit with sigma1 held at the passivity bound ``4*sigma2*fc/(fs - fc)`` of
    its friction when it came out beyond it and the record leaves it loose (a
    non-passive friction map can feed energy into the axis): said in its profile. The
    bound is sufficient for passivity, not necessary: a sigma1 the record puts beyond
    it, its whole interval too, is kept, and its profile carries the bound
    (``passivity_bound``), which the fit's notes give beside it."""
    m = res.model
    if m.is_passive:
        return res
    bound = min(m.passivity_bound())
    prof = dict(res.profiles)
    p = dict(prof.get("sigma1") or {"ci95": [None, None]})
    lo = (p.get("ci95") or [None, None])[0]
    if lo is not None and lo > bound:
        p["passivity_bound"] = bound
        prof["sigma1"] = p
        return replace(res, profiles=prof)
    p.update(value=bound, fitted=m.sigma1, determined=False, how="passivity bound")
    prof["sigma1"] = p
    return replace(res, model=m.with_friction(sigma1=bound), profiles=prof)


def _identify(rec: Any, mass: float | None, force_constant: float, cutoff_hz: float | None,
              controller: dict[str, Any] | None, backend: Any, profiles: bool
              ) -> BaseFitResult:
    from .inverse import inverse_starts

    start, other = inverse_starts(
        rec, mass=mass, force_constant=force_constant, cutoff_hz=cutoff_hz,
        controller=controller, backend=backend, sliding=SLIDING)
    sig = R.prepare(rec, start, cutoff_hz=cutoff_hz, backend=backend)
    res = _with_sized_loads(sig, start, mass is None)
    if res.floor_ratio > DRAG_FAR and other is not None:
        alt = _with_sized_loads(sig, other, mass is None)
        res = alt if alt.rms < DRAG_CUT * res.rms else res
    # the band depends on the mass (the position's noise twice differentiated times
    # the mass against the force's noise): a start far off in mass reads the record in
    # the wrong band, and the fit follows the acceleration's noise; read it again in
    # the band of the fitted model, from the grid around it, until the band settles (a
    # feed record's start of 0.066 kg for 22 kg: 200 Hz, then 1.09 kg and 104 Hz, where
    # the fit of 22.1 kg stopped at 1.19 N rms; in its own band of 26 Hz, 0.14 N)
    for _ in range(BAND_READS):
        sig2 = R.prepare(rec, res.model, cutoff_hz=cutoff_hz, backend=backend)
        if not abs(math.log(sig2.cutoff_hz / sig.cutoff_hz)) > math.log(BAND_CHANGE):
            break
        res = fit_base(sig2, res.model, free_mass=mass is None, profiles=False)
        sig = sig2
    if not profiles:
        return res
    shift = sampling_shift(rec, res, cutoff_hz=cutoff_hz, backend=backend,
                           free_mass=mass is None)
    return with_profiles(sig, res, shift)


#: A fit further than this from the record's noise floor (its rms over the floor: the
#: fit's own words say "at the noise floor" within it) is
#: tried again with a quadratic drag beside the base, and the drag kept when it halves
#: the residual's rms (:data:`DRAG_CUT`). The linear start keeps a drag by itself only
#: when it brings back a Coulomb level below zero (or halves the robust scale): on drag
#: records of the independent plant whose levels stayed positive but 20-70 % low, the
#: fit ended 3.4-5 times the floor; with the drag, 1.0-1.5 times and every level and
#: the mass within 0.5 %.
DRAG_FAR = 1.5
DRAG_CUT = 0.5


def _with_sized_loads(sig: R.Signals, start: Model, free_mass: bool) -> BaseFitResult:
    """The base fitted from ``start``, and again once the loads it holds are sized
    (:func:`_loads_sized`)."""
    res = fit_base(sig, start, free_mass=free_mass, profiles=False)
    sized = _loads_sized(sig, res)
    if sized is not res.model:
        res = fit_base(sig, sized, free_mass=free_mass, profiles=False)
    return res


#: Golden-section steps that place a spring's rest position, and the iterations of the
#: base's polish at each.
REST_STEPS = 10
REST_ITER = 12

#: Most the polish of a load's size moves the linear start's (a factor either way).
LOAD_FACTOR = 1.5


def _loads_sized(sig: R.Signals, res: BaseFitResult) -> Model:
    """The fit's model with the loads its linear start took up sized on the record (a
    spring placed and stiffened, a drag's coefficient polished): the same model when
    it holds none."""
    found = {e["effect"] for e in res.model.effects}
    model = _spring_rest(sig, res) if SPRING in found else res.model
    if DRAG in found:
        model = _load_scaled(sig, model, Polisher(sig, list(res.names)), DRAG, "coefficient")
    return model


def _load_scaled(sig: R.Signals, model: Model, polish: Polisher, effect: str,
                 name: str) -> Model:
    """``model`` with the ``name`` of its ``effect`` where the base polished beside it
    fits best, within :data:`LOAD_FACTOR` of its value (golden section on the log)."""
    effects = list(model.effects)
    k = next(k for k, e in enumerate(effects) if e["effect"] == effect)

    def sized(value: float) -> Model:
        return model.replace(effects=effects[:k] + [{**effects[k], name: value}]
                             + effects[k + 1:])

    u0, du = math.log(float(effects[k][name])), math.log(LOAD_FACTOR)
    return sized(math.exp(golden(lambda u: polish(sized(math.exp(u)), REST_ITER)[0],
                                 u0 - du, u0 + du, REST_STEPS - 2)))


def _spring_rest(sig: R.Signals, res: BaseFitResult) -> Model:
    """The fit's model with its spring's rest position and stiffness where the record
    puts them.

    The linear start cannot place the rest position: while the axis moves, a preload
    beyond the stroke's middle and a difference of the directions' Coulomb levels look
    alike. At standstill they do not (the bristles hold what the spring pushes with),
    so the rest position is searched over the stroke (and the start's rest position)
    and half of it beyond either end, then the stiffness within a factor of 1.5 of the
    start's (where the mass is little excited the start shares it with the mass), the
    base polished at each (golden section on the residual's rms)."""
    effects = list(res.model.effects)
    k = next(k for k, e in enumerate(effects) if e["effect"] == SPRING)
    spring, others = dict(effects[k]), effects[:k] + effects[k + 1:]
    x = sig.x[sig.mask]
    x0 = float(spring["x0"])
    lo, hi = min(float(np.min(x)), x0), max(float(np.max(x)), x0)
    span = max(hi - lo, 1e-9)

    def placed(**kw: float) -> Model:
        return res.model.replace(effects=others + [{**spring, **kw}])

    polish = Polisher(sig, list(res.names))
    spring["x0"] = golden(lambda u: polish(placed(x0=u), REST_ITER)[0],
                          lo - 0.5 * span, hi + 0.5 * span, REST_STEPS)
    return _load_scaled(sig, placed(), polish, SPRING, "stiffness")


def sampling_shift(rec: Any, res: BaseFitResult, *, cutoff_hz: float | None, backend: Any,
                   free_mass: bool) -> dict[str, float]:
    """How far each parameter moves when the record is read at half its rate (every
    other sample), the fit polished from ``res``: the bristles advanced over twice the
    interval show what the sampling does to a parameter (a Stribeck speed crossed in a
    few samples, presliding faster than the record), a bias the noise does not show.
    Empty for a record too short to halve."""
    from ..io import Recording

    if len(rec) < 2 * MIN_HALF:
        return {}
    cols = {c: getattr(rec, c)[::2] for c in rec.columns}
    try:
        half = Recording(**cols)
        sig = R.prepare(half, res.model, cutoff_hz=cutoff_hz, backend=backend)
        other = fit_base(sig, res.model, free_mass=free_mass, profiles=False, grid=False)
    except (ValueError, ArithmeticError):  # pragma: no cover - the halved record refused
        return {}
    return {n: _value(other.model, n) - _value(res.model, n) for n in res.names}
