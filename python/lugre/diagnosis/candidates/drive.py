"""Effects of the drive's force path: a force (torque) ripple that scales with the
current, an amplifier that saturates, and friction that grows with the force the
transmission carries."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ... import units as U
from ...vocabulary import COGGING, CURRENT_LIMIT, FORCE_RIPPLE, LOAD_FRICTION
from .. import residual as R
from ..residual import Signals, position_sums
from .base import Candidate, Context, by, by_current
from .linear import mass_both_ways
from .position import Cogging, by_pitch, periodic_sizes, pitch_bands
from .probe import amps, currents, hide, share, two_ways, under
from .secant import _Secant

__all__ = ["BRAKING_SHARE", "CurrentLimit", "ForceRipple", "LoadFriction"]

#: Least share of the samples where the drive brakes the axis for a friction growing
#: with the drive's force to be told from a payload (as :func:`mass_alternative`).
BRAKING_SHARE = 0.05


class ForceRipple(Candidate):
    """``K_F*i*(1 + a*sin(2*pi*x/p + phase))``: the columns are the motor force times
    ``sin`` and ``cos`` of ``2*pi*x/p``, the pitch from the periodogram of the residual
    weighted by the motor force. A cogging is the same periodic force at any current; a
    ripple vanishes with the current and changes sign with it."""

    effect = FORCE_RIPPLE
    chooses = True
    #: 1 % of the motor force: a ripple under it matters little to a loop, and what a
    #: lag's misfit leaves along a stroke read as 0.1 % ripple on a clean feed record
    least_force = 10.0 / 3.0
    least_force_why = "a ripple this small is within what other misfits leave along the stroke"
    signature = ("a force periodic in position that grows with the motor current and "
                 "changes sign with it (force-constant or torque ripple)")

    def choose(self, r: np.ndarray, ctx: Context) -> Any:
        ks = Cogging()._kgrid(ctx)
        if ks.size == 0:
            return None
        m = ctx.sig.mask
        step = max(1, int(m.sum() // 6000))
        x = ctx.sig.x[m][::step]
        fm = ctx.sig.fm_f[m][::step]
        w = fm * (r[m][::step] - np.mean(r[m]))
        span = max(ctx.xrange[1] - ctx.xrange[0], 1e-9)
        p = _power(ctx, x, w, float(ks[0]), 0.25 / span, ks.size)
        k0 = float(ks[int(np.argmax(p))])
        lo, hi = k0 - 0.3 / span, k0 + 0.3 / span
        pf = _power(ctx, x, w, lo, (hi - lo) / 30, 31)
        return 1.0 / float(np.linspace(lo, hi, 31)[int(np.argmax(pf))])

    def columns(self, h: Any, ctx: Context) -> np.ndarray:
        ph = 2.0 * np.pi * ctx.sig.x / h
        fm = ctx.sig.fm
        return ctx.sig.filt(np.column_stack([fm * np.sin(ph), fm * np.cos(ph)]))

    def to_effects(self, h: Any, beta: np.ndarray, ctx: Context) -> list[dict[str, Any]]:
        # the residual is K_F*i - (model force): a ripple adds K_F*i*a*sin(...) to what
        # acts, so the residual of the model without it holds -K_F*i*a*sin(...)
        amp = float(math.hypot(beta[0], beta[1]))
        phase = float(math.atan2(-beta[1], -beta[0]))
        return [{"effect": FORCE_RIPPLE, "amplitude": min(amp, 0.95), "pitch": float(h),
                 "phase": phase}]

    def describe(self, h: Any, beta: np.ndarray, ctx: Context) -> str:
        pitch = U.fmt(float(h), "m")
        return (f"The residual weighted by the motor {U.force_words()} peaks at a pitch of "
                f"{pitch}: the periodic part grows with the current (unlike a cogging).")

    figure = by("x", "position [m]")

    def where(self, h: Any, beta: np.ndarray, ctx: Context) -> dict[str, Any]:
        return {"position": list(ctx.xrange), "time": None, "velocity": None}

    def limit(self, ctx: Context, sizes: Any) -> dict[str, Any] | None:
        span = max(ctx.xrange[1] - ctx.xrange[0], 1e-9)
        ks = np.geomspace(1.5 / span, max(Cogging.kmax(ctx), 2.0 / span), 6)
        amps_ = np.array([share(a) for a in periodic_sizes(
            sizes, lambda p: self.columns(p, ctx), [1.0 / k for k in ks])])
        seen = np.isfinite(amps_)
        b = float(np.max(amps_[seen])) if seen.any() else math.inf
        return {**hide(self.effect, b, "-", f"a {U.force_words()} ripple " + pitch_bands(
                           ks, 100 * amps_, "{:.2g} % of the motor " + U.force_words(),
                           "{:.2g} %"),
                       experiment=("slow constant-speed passes under a steady load (a "
                                   "current well away from zero) show the ripple apart "
                                   "from a cogging")),
                "by_pitch": by_pitch(ks, amps_)}


def _power(ctx: Context, x: np.ndarray, w: np.ndarray, k0: float, dk: float,
           n: int) -> np.ndarray:
    """Power of the sinusoids of ``w`` over ``x`` at ``k0 + j*dk`` (their sums; the
    weights of the ripple's columns taken as even over a period)."""
    s, c = position_sums(ctx.sig, x, w, k0, dk, n)
    return np.asarray(s) ** 2 + np.asarray(c) ** 2


#: Coefficients on a current limit's secant read as the grid point's limit itself.
NEAR_ONE = (0.8, 1.25)

#: Least share of the samples in motion a named current limit clips: the limits named
#: right on rotary records clip 5.8 % and 7.9 %, the generator's smallest 0.5 %; a limit
#: at 5.68 A named on a feed record where a payload and an offset were missing clipped
#: 11 of 30 000 (0.04 %), the peaks that any misfit of the accelerations leaves. Read on
#: the exact form the joint refit leaves, not on the selection: there a clip of 0.15 %
#: beside a payload and a delay kept the payload reading alike speeding up and braking
#: until the joint refit dropped the clip (stress seed 31, case 048).
LEAST_CLIPPED = 0.002


def _clip_of_excess(ia: np.ndarray, c: float, b: float) -> float:
    """The limit [A] whose excess ``max(|i| - limit, 0)`` over the currents ``ia`` has
    ``b`` times the rms of the excess over ``c`` (bisection: the rms falls as the limit
    rises)."""
    def excess(limit: float) -> float:
        return float(np.sqrt(np.mean(np.maximum(ia - limit, 0.0) ** 2)))

    want = b * excess(c)
    lo, hi = (c, float(np.max(ia))) if b < 1.0 else (0.0, c)
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if excess(mid) > want else (lo, mid)
    return 0.5 * (lo + hi)


class CurrentLimit(_Secant):
    """``K_F*clip(i, -c, c)``: the record holds the command, the axis gets less above
    the limit. Searched over the percentiles of the recorded current (a saturated
    drive's integrator keeps the command above the limit for long), then on a finer
    grid around the best; a record that never reaches a limit cannot show one."""

    effect = CURRENT_LIMIT
    param = "current"
    #: a clip of the few highest currents is what a lag or a resonance does to the
    #: peaks too: kept as a minor correction it took a current lag's place
    may_be_minor = False
    #: 1 % of the motor force: a clip of the peaks under it is what a mass error, a lag
    #: or a resonance leaves at the peaks of the current as well
    least_force = 10.0 / 3.0
    least_force_why = "a clip of the peaks this small is what other misfits leave there"
    signature = ("the drive's force stops growing above a current: the logged command "
                 "asks for more than acts at the peaks of the current")

    def grid(self, ctx: Context) -> np.ndarray | None:
        ia = currents(ctx)
        if ia.size == 0 or not float(np.max(ia)) > 0:
            return None
        return np.percentile(ia, [20.0, 35.0, 50.0, 65.0, 75.0, 85.0, 92.0, 96.0, 98.5, 99.5])

    def effect_at(self, h: Any) -> dict[str, Any]:
        return {"effect": CURRENT_LIMIT, "current": float(h)}

    check_rank = 2

    def check(self, scorer: Any, terms: list[Any], k: int, ev: Any, ctx: Context
              ) -> dict[str, Any] | None:
        return clip_both_ways(scorer, terms, k, ev, ctx)

    def refusal(self, chk: dict[str, Any]) -> str | None:
        if not chk["not_limit"]:
            return None
        return (f"it reads {chk['rising']:+.2g} while the current rises toward its peaks "
                f"and {chk['falling']:+.2g} while it falls: a limit clips both alike, a "
                "force that lags the current does not")

    def exact_refusal(self, h: Any, beta: np.ndarray, ctx: Context) -> str | None:
        # (refitted with the base, a coefficient under one maps the limit higher each
        # pass: a misfit of the peaks walks it up to the record's largest current)
        c = self.parameter(h, beta, ctx)
        ia = currents(ctx)
        clipped = int(np.sum(ia > c))
        if clipped >= LEAST_CLIPPED * ia.size:
            return None
        return (f"a limit at {amps(c)} clips {clipped} of the record's {ia.size} samples "
                "in motion: a clip of the very peaks is what a lag, a resonance or a mass "
                "error leaves there too")

    def from_secant(self, h: Any, b: float) -> Any:
        # the clipped excess is far from linear in the limit: the limit is the grid
        # point's, found by the held-out profile (coarse, then fine)
        return float(h)

    def parameter(self, h: Any, beta: np.ndarray, ctx: Context) -> Any:
        """The limit whose clipped excess has the rms of ``beta`` times the excess at
        ``h`` (the grid point's when ``beta`` is within :data:`NEAR_ONE` of 1): a clip at
        1.42 A of a record whose peaks reach 5.4 A, taken at a coefficient of 0.06, is a
        limit just under the peaks, not a drive clipped at 1.42 A (its exact form
        ruined a coupling's story on a fitted base). A coefficient of zero or below
        maps to the largest current: a limit that clips nothing."""
        b, c = float(beta[0]), float(h)
        if NEAR_ONE[0] <= b <= NEAR_ONE[1]:
            return c
        ia = currents(ctx)
        return _clip_of_excess(ia, c, b)

    def describe(self, h: Any, beta: np.ndarray, ctx: Context) -> str:
        c = self.parameter(h, beta, ctx)
        return (f"Above {amps(c)} ({c * ctx.model.force_constant:.3g} "
                f"{U.si('N')}) the drive gives no more {U.force_words()}.")

    figure = by_current

    def limit(self, ctx: Context, sizes: Any) -> dict[str, Any] | None:
        ia = currents(ctx)
        top = float(np.max(ia)) if ia.size else 0.0
        return hide(self.effect, math.inf, "A",
                    f"a current limit above {amps(top)} (the largest current of this "
                    "record; a limit it never reached is not determined)",
                    experiment="moves that ask for the drive's peak current")


def _payload_does_as_well(scorer: Any, terms: list[Any], k: int, ev: Any,
                          ctx: Any) -> bool:
    """Whether a payload in place of the load-friction term ``terms[k]`` gains at least
    four fifths of what the term gains on the held-out stretches (a friction growing
    with the drive's force on constant-speed feeds scales the levels, no payload)."""
    from .base import Term
    from .linear import Mass

    others = terms[:k] + terms[k + 1:]
    mass = Term(cand=Mass(), h=None, X=Mass().columns(None, ctx))
    none = scorer.evaluate(others).score
    return bool(none - scorer.evaluate(others + [mass]).score >= 0.8 * (none - ev.score))


def clip_both_ways(scorer: Any, terms: list[Any], k: int, ev: Any,
                   ctx: Any) -> dict[str, Any] | None:
    """Is the current-limit term ``terms[k]`` a limit, the same while the current rises
    toward its peaks and while it falls? A clip takes ``|i| - c`` away wherever the
    current is over the limit, either way; a force lagging the current is short of it
    while the current rises and beyond it while it falls, which a clip of the peaks
    partly resembles. The term is refitted, jointly with the base and the other terms,
    on the samples over the limit where ``|i|`` rises and on those where it falls; when
    both determine it (standard errors under a quarter of the full fit's), differ by
    more than four combined standard errors and one side reads under a third of the
    other (or the other sign), the term is no limit. Returns the figures, or None when
    the record cannot tell.
    """
    sig = ctx.sig
    m = scorer.mask
    over = m & (np.abs(terms[k].X[:, 0]) > 0.05 * float(np.max(np.abs(terms[k].X[m, 0]))))
    rate = np.gradient(np.abs(sig.fm_f))
    rising, falling = over & (rate > 0), over & (rate < 0)
    if min(rising.sum(), falling.sum()) < 20:
        return None
    out = two_ways(scorer, terms, k, ev, {"rising": rising, "falling": falling})
    if out is None:
        return None
    a, b = out["rising"], out["falling"]
    # (a real limit found at a grid point near it reads 1.1 rising and 0.74 falling; a
    # 64 Hz lag read 0.27 and 0.02: one side a third of the other or less, or of the
    # other sign, is no clip)
    lopsided = a * b <= 0 or min(abs(a), abs(b)) < CLIP_SIDES * max(abs(a), abs(b))
    out["not_limit"] = bool(out.pop("apart") and lopsided)
    return out


#: A clip's coefficient where the current rises and where it falls: one side under this
#: share of the other is no clip.
CLIP_SIDES = 1.0 / 3.0


class LoadFriction(_Secant):
    """Friction levels that grow with the force the transmission carries,
    ``fc + c*|K_F*i|``: searched as the change of the residual that a coefficient
    makes (the bristle state included), over a grid of coefficients."""

    effect = LOAD_FRICTION
    param = "coefficient"
    scales_levels = False
    #: 1 % of the motor force: below, its column is what a mass off by a percent and
    #: the plant's own discretisation leave (clean records of an independent plant read
    #: 0.4-0.8 % with a believed mass 1 % off; 2 % load friction reads 1.8 %)
    least_force = 10.0 / 3.0
    least_force_why = ("a friction growing with the drive's force this small is what a "
                       "mass off by a percent leaves")
    signature = ("friction that grows with the drive's force: more friction where the "
                 "axis is accelerated or loaded, in the direction of motion")

    def grid(self, ctx: Context) -> np.ndarray | None:
        return np.array([0.01, 0.03, 0.1, 0.3])

    def _signals(self, ctx: Context) -> Signals:
        """The record with the motor force the model needs in place of the logged one.

        The column is a share of the force the transmission carries. Taken from the
        logged current it holds the residual itself (its noise and whatever the base
        misses, in the drive's direction), and a regression on it explains any
        residual in part: on clean records fitted by ``lugre fit`` it took a third of
        every level and of the mass. The force the model needs (mass times acceleration
        plus friction and effects, from the measured motion) is what the transmission
        carries where the model is right, and shares nothing with the residual."""
        key = ("needed_force", id(ctx.model))
        if key not in ctx.extra:
            sig = ctx.sig
            ctx.extra[key] = sig.with_force(sig.fm_f - R.residual(ctx.model, sig))
        return ctx.extra[key]


    check_rank = 1

    def check(self, scorer: Any, terms: list[Any], k: int, ev: Any, ctx: Context
              ) -> dict[str, Any] | None:
        # where the drive (almost) never brakes the axis, |F| against the motion is F:
        # a payload beside friction levels that much higher, the simpler story, which
        # the mass's finding tells with this as its look-alike
        sig, m = ctx.sig, scorer.mask
        brake = float(np.mean((sig.fm_f * sig.vf)[m] < 0)) if m.any() else 0.0
        if brake < BRAKING_SHARE and _payload_does_as_well(scorer, terms, k, ev, ctx):
            return {"braking_share": brake, "like_payload": True, "not_payload": False}
        # the same refit on the samples where the drive speeds the axis up and where
        # it brakes it: a friction growing with the drive's force reads the same
        # coefficient on both, a payload (or a level error) does not
        return mass_both_ways(scorer, terms, k, ev, ctx)

    def refusal(self, chk: dict[str, Any]) -> str | None:
        if chk.get("like_payload"):
            return (f"the drive brakes the axis on {100 * chk['braking_share']:.1f} % of "
                    "the samples only: a friction growing with its force cannot be told "
                    f"from a payload beside higher friction levels, and the payload (one "
                    "parameter) is told, with this as its look-alike")
        if not chk["not_payload"]:
            return None
        return (f"the coefficient reads {chk['speeding_up']:+.2g} where the drive speeds "
                f"the axis up and {chk['braking']:+.2g} where it brakes: a friction "
                "growing with the drive's force is the same both ways")

    def effect_at(self, h: Any) -> dict[str, Any]:
        return {"effect": LOAD_FRICTION, "coefficient": float(h)}

    def from_secant(self, h: Any, b: float) -> Any:
        return float(max(b * float(h), 0.0))

    figure = by("v", "velocity [m/s]")

    def describe(self, h: Any, beta: np.ndarray, ctx: Context) -> str:
        c = self.from_secant(h, float(beta[0]))
        return (f"The friction levels grow by {100 * c:.2g} % of the drive's "
                f"{U.force_words()}.")

    def limit(self, ctx: Context, sizes: Any) -> dict[str, Any] | None:
        h0 = 0.05
        b = h0 * float(sizes([self.columns(h0, ctx)[:, 0]])[0])
        return hide(self.effect, b, "-", "a friction growing with the drive's "
                    f"{U.force_words()} {under(100 * b, '{:.2g} %')} of it",
                    experiment=("moves at one speed under different loads or "
                                "accelerations"))


#: The cogging's look-alike among these: told apart by how it scales with the current.
LOOKALIKES = {FORCE_RIPPLE: COGGING}
