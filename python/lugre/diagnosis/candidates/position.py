"""Effects that live along the stroke: cogging and position-dependent friction."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ... import units as U
from ...vocabulary import COGGING, GRAVITY, OFFSET, POSITION_FRICTION
from ..residual import position_sums
from .base import Candidate, Context, Term, by, rows_of
from .probe import AT_ONCE, FixedInPosition, hide, in_batches, share, under

__all__ = ["Cogging", "Gravity", "PositionFriction"]

#: Hat columns built and low-passed at once (every column is filtered on its own: the
#: same numbers in any grouping).
_AT_ONCE = 8


class Gravity(FixedInPosition, Candidate):
    """A load's weight on a joint, ``torque*sin(x + phase)``: two columns, ``sin(x)``
    and ``cos(x)``. One turn is known, so a record that spans a fraction of a turn still
    shows the curvature that tells it from a spring and an offset (which it contains)."""

    effect = GRAVITY
    supersedes = (OFFSET,)
    signature = ("a torque following the sine of the joint angle, the same in both "
                 "directions of motion and at rest (a load's weight)")

    def columns(self, h: Any, ctx: Context) -> np.ndarray:
        x = ctx.sig.x
        return ctx.sig.filt(np.column_stack([np.sin(x), np.cos(x)]))

    def to_effects(self, h: Any, beta: np.ndarray, ctx: Context) -> list[dict[str, Any]]:
        torque = float(math.hypot(beta[0], beta[1]))
        phase = float(math.atan2(beta[1], beta[0]))
        return [{"effect": GRAVITY, "torque": torque, "phase": phase}]

    def where(self, h: Any, beta: np.ndarray, ctx: Context) -> dict[str, Any]:
        return {"position": list(ctx.xrange), "time": None, "velocity": None}

    figure = by("x", "position [m]")

    def describe(self, h: Any, beta: np.ndarray, ctx: Context) -> str:
        torque = float(math.hypot(beta[0], beta[1]))
        level = -float(math.atan2(beta[1], beta[0]))
        return (f"At most {U.fmt(torque, 'N')}; it vanishes where the load hangs level "
                f"with the joint, at {U.fmt(level, 'm')} of the axis's zero.")

    def limit(self, ctx: Context, sizes: Any) -> dict[str, Any] | None:
        x = ctx.sig.x
        xm = 0.5 * (ctx.xrange[0] + ctx.xrange[1])
        b = float(np.max(sizes([ctx.sig.filt(np.sin(x - xm)), ctx.sig.filt(np.cos(x - xm))])))
        return hide(self.effect, b, "N", f"a gravity torque {under(b, '{:.2g} N m')}",
                    experiment="slow moves over a large part of a turn in both directions")


def periodic_sizes(sizes: Any, columns: Any, pitches: list[float]) -> np.ndarray:
    """Per pitch, the smallest amplitude the search would name at any phase: the
    larger of the sine's and the cosine's, each judged with both columns free, as the
    search fits them (``columns(pitch)``: the sine and cosine columns of a pitch, built
    a few pitches at a time)."""
    def judge(ps: list[float]) -> np.ndarray:
        cols = [columns(p) for p in ps]
        fits = [Term(cand=None, h=None, X=X) for X in cols]
        both = sizes([X[:, j] for X in cols for j in (0, 1)],
                     fits=[f for f in fits for _ in (0, 1)])
        return np.max(np.asarray(both, float).reshape(len(cols), 2), axis=1)
    return in_batches(judge, list(pitches), AT_ONCE // 2)


def by_pitch(ks: np.ndarray, amps: np.ndarray, scale: float = 1.0) -> dict[str, Any]:
    """The limit at each pitch searched, longest first (``pitch`` [m], ``smallest`` in
    the entry's unit, None where any size is hidden): a periodic force's limit depends
    on its pitch, and the largest over the range overstates it at most pitches."""
    order = np.argsort(ks)
    return {"pitch": [float(1.0 / ks[j]) for j in order],
            "smallest": [float(scale * amps[j]) if np.isfinite(amps[j]) else None
                         for j in order]}


def pitch_bands(ks: np.ndarray, amps: np.ndarray, fmt: str, then: str | None = None) -> str:
    """The limits of the longer and the shorter half of the pitches in words: "under
    0.3 N at pitches 12 to 150 mm, under 0.9 N at 1.2 to 12 mm" (``then``: the format
    of the second, ``fmt`` by default)."""
    u, k = U.position_unit()
    order = np.argsort(ks)  # (longest pitch first)
    halves = (order[: (ks.size + 1) // 2], order[ks.size // 2:])
    out = []
    for j, half in enumerate(halves):
        a = amps[half]
        seen = a[np.isfinite(a)]
        b = float(np.max(seen)) if seen.size == a.size else float("inf")
        lead = "at pitches " if j == 0 else "at "
        out.append(f"{under(b, fmt if j == 0 else then or fmt)} {lead}{k / ks[half].max():.3g} to "
                   f"{k / ks[half].min():.3g} {u}")
    return ", ".join(out)


class Cogging(FixedInPosition, Candidate):
    effect = COGGING
    chooses = True
    signature = "a force periodic in position, independent of the direction of motion"

    def _kgrid(self, ctx: Context) -> np.ndarray:
        """Spatial frequencies [1/m] the record resolves.

        Up to what the slow, well-moving fifth of the record passes within the filter
        band (a pitch ``p`` crossed at speed ``v`` is a force at ``v/p`` Hz), and at
        least 20 encoder counts a period; down to 1.5 periods over the stroke.
        """
        span = max(ctx.xrange[1] - ctx.xrange[0], 1e-9)
        kmax = self.kmax(ctx)
        kmin = 1.5 / span
        if kmax <= kmin:
            return np.array([])
        return np.arange(kmin, kmax, 0.25 / span)

    @staticmethod
    def kmax(ctx: Context) -> float:
        """Highest spatial frequency [1/m] the record resolves (see :meth:`_kgrid`)."""
        sig = ctx.sig
        moving = np.abs(sig.vf[sig.mask])
        moving = moving[moving > 0.05 * max(float(moving.max()), 1e-12)]
        v_slow = float(np.percentile(moving, 20)) if moving.size else 1.0
        q = max(sig.info.get("quantum", 0.0), 1e-9)
        return min(1.0 / (20.0 * q), 0.7 * sig.cutoff_hz / max(v_slow, 1e-9))

    @staticmethod
    def _power(r: np.ndarray, x: np.ndarray, k0: float, dk: float, n: int,
               sig: Any) -> np.ndarray:
        """Power of the best sinusoid of ``r`` over ``x`` at ``k0 + j*dk``, ``j < n``
        (least squares on sin and cos)."""
        rs, rc, ss, cc, sc = position_sums(sig, x, r, k0, dk, n, squares=True)
        det = ss * cc - sc * sc
        bs = (cc * rs - sc * rc) / det
        bc = (ss * rc - sc * rs) / det
        return bs * rs + bc * rc

    def choose(self, r: np.ndarray, ctx: Context) -> Any:
        ks = self._kgrid(ctx)
        lead = ctx.extra.get("screw_lead")
        if ks.size == 0:
            return None
        m = ctx.sig.mask
        step = max(1, int(m.sum() // 6000))
        x = ctx.sig.x[m][::step]
        rr = r[m][::step] - np.mean(r[m])
        dk = 0.25 / max(ctx.xrange[1] - ctx.xrange[0], 1e-9)  # the step of _kgrid
        p = self._power(rr, x, float(ks[0]), dk, ks.size, ctx.sig)
        k0 = ks[int(np.argmax(p))]
        span = ctx.xrange[1] - ctx.xrange[0]
        lo, hi = k0 - 0.3 / span, k0 + 0.3 / span
        fine = np.linspace(lo, hi, 31)
        pf = self._power(rr, x, lo, (hi - lo) / 30, 31, ctx.sig)
        if lead:  # one revolution of the screw and its harmonics: always tried
            fine = np.concatenate([fine, np.arange(1, 5) / float(lead)])
            kl = abs(1.0 / float(lead))  # (the power is even in k)
            pf = np.concatenate([pf, self._power(rr, x, kl, kl, 4, ctx.sig)])
        k1 = float(fine[int(np.argmax(pf))])
        self.spectrum = (ks, p)
        return 1.0 / k1

    def describe(self, h: Any, beta: np.ndarray, ctx: Context) -> str:
        u, k = U.position_unit()
        return (f"The residual's spectrum over position peaks at a pitch of {h * k:.4g} {u} "
                f"(searched from {k / self.kmax(ctx):.3g} {u}, what the slowest fifth of "
                "the motion resolves in the filter band, to the stroke).")

    figure = by("x", "position [m]")

    def columns(self, h: Any, ctx: Context) -> np.ndarray:
        ph = 2.0 * np.pi * ctx.sig.x / h
        return ctx.sig.filt(np.column_stack([np.sin(ph), np.cos(ph)]))

    def to_effects(self, h: Any, beta: np.ndarray, ctx: Context) -> list[dict[str, Any]]:
        amp = float(math.hypot(beta[0], beta[1]))
        phase = float(math.atan2(beta[1], beta[0]))
        return [{"effect": COGGING, "amplitude": amp, "pitch": float(h), "phase": phase}]

    def limit(self, ctx: Context, sizes: Any) -> dict[str, Any] | None:
        span = ctx.xrange[1] - ctx.xrange[0]
        kmax = self.kmax(ctx)
        ks = np.geomspace(1.5 / max(span, 1e-9), max(kmax, 2.0 / max(span, 1e-9)), 8)
        amps = periodic_sizes(sizes, lambda p: self.columns(p, ctx), [1.0 / k for k in ks])
        seen = np.isfinite(amps)
        b = float(np.max(amps[seen])) if seen.any() else float("inf")
        blind = ""
        u, k = U.position_unit()
        if seen.any() and not seen.all():
            pb = k / ks[~seen]
            blind = (f" (of any size at pitches near {pb.min():.3g} to {pb.max():.3g} "
                     f"{u}: what the friction levels cannot absorb lies in one "
                     "held-out stretch)")
        txt = (f"a cogging {pitch_bands(ks, amps, '{:.2g} ' + U.si('N'))}{blind}, or any at "
               f"pitches under {k / kmax:.3g} {u} (faster than the filter band at this "
               "record's slowest motion),")
        slow = "a few hundredths of a rad/s" if U.is_rotary() else "a few mm/s"
        return {**hide(self.effect, b, "N", txt, experiment=(
            f"slow constant-speed passes ({slow}) show short pitches")),
            "by_pitch": by_pitch(ks, amps)}

    def where(self, h: Any, beta: np.ndarray, ctx: Context) -> dict[str, Any]:
        return {"position": list(ctx.xrange), "time": None, "velocity": None}


class PositionFriction(Candidate):
    effect = POSITION_FRICTION
    scales_levels = True
    signature = ("a change of the Coulomb/static friction level along the guideway: it "
                 "changes sign with the direction of motion and depends on position")

    def knots(self, ctx: Context) -> np.ndarray:
        lo, hi = ctx.xrange
        n = int(np.clip(round((hi - lo) / 0.01), 8, 24)) + 1
        return np.linspace(lo, hi, n)

    def columns(self, h: Any, ctx: Context) -> np.ndarray:
        """The hat of each knot times the Coulomb/static friction, low-passed; built and
        filtered a few columns at a time into the result (on a long record the 25
        columns are 200 MB, and the hats and their product whole would triple it)."""
        out = np.empty((ctx.sig.x.size, self.knots(ctx).size))
        for js, cols in self._hats(ctx):
            out[:, js] = cols
        return out

    def _hats(self, ctx: Context) -> Any:
        """The columns of :meth:`columns` a few at a time: ``(slice, columns)``."""
        kn = self.knots(ctx)
        x = np.clip(ctx.sig.x, kn[0], kn[-1])
        eye = np.eye(kn.size)
        for j0 in range(0, kn.size, _AT_ONCE):
            js = slice(j0, min(j0 + _AT_ONCE, kn.size))
            hats = np.empty((x.size, js.stop - js.start), order="F")  # (columns whole)
            for i, j in enumerate(range(js.start, js.stop)):
                hats[:, i] = np.interp(x, kn, eye[j])
            hats *= ctx.fcs[:, None]
            yield js, ctx.sig.filt(hats)

    def prior_tol(self, h: Any, ctx: Context) -> np.ndarray | None:
        return np.full(self.knots(ctx).size, 0.3)

    def to_effects(self, h: Any, beta: np.ndarray, ctx: Context) -> list[dict[str, Any]]:
        kn = self.knots(ctx)
        scale = np.maximum(1.0 + np.asarray(beta, float), 0.05)
        return [{"effect": POSITION_FRICTION, "positions": [float(p) for p in kn],
                 "scale": [float(s) for s in scale]}]

    def where(self, h: Any, beta: np.ndarray, ctx: Context) -> dict[str, Any]:
        kn = self.knots(ctx)
        dev = np.abs(np.asarray(beta, float))
        big = np.flatnonzero(dev >= 0.25 * dev.max()) if dev.max() > 0 else np.array([])
        if big.size == 0:
            return {"position": None, "time": None, "velocity": None}
        lo = kn[max(big[0] - 1, 0)]
        hi = kn[min(big[-1] + 1, kn.size - 1)]
        return {"position": [float(lo), float(hi)], "time": None, "velocity": None}

    def limit(self, ctx: Context, sizes: Any) -> dict[str, Any] | None:
        # a change over a tenth of the stroke each side of the mean position, as the
        # search reads it: with every knot's hat free within its prior
        kn = self.knots(ctx)
        span = ctx.xrange[1] - ctx.xrange[0]
        near = (np.abs(kn - np.mean(ctx.sig.x)) < 0.1 * span).astype(float)
        # the hats kept at the rows the scorer reads only (all its fits read of them),
        # built a few at a time: whole, they are 200 MB on a million samples
        step = int(ctx.extra.get("rows_step", 1))
        hats = np.empty((len(range(0, ctx.sig.x.size, step)), kn.size))
        bump = np.zeros(ctx.sig.x.size)
        for js, cols in self._hats(ctx):
            hats[:, js] = rows_of(cols, step)
            bump += cols @ near[js]
        ft = Term(cand=None, h=None, X=hats, prior=self.prior_tol(None, ctx))
        b = share(float(sizes([bump], fits=[ft])[0]))
        return hide(self.effect, b, "-", f"a friction change {under(100 * b, '{:.2g} %')} "
                    "over a tenth of the stroke")


PositionFriction.figure = by("x", "position [m]")  # type: ignore[method-assign]
