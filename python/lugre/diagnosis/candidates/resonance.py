"""A compliant coupling: a load swinging against the motor."""

from __future__ import annotations

from typing import Any

import numpy as np

from ...vocabulary import RESONANCE
from .base import Context, grid_interval, objects
from .probe import hide, in_batches
from .secant import _Secant

__all__ = ["Resonance"]


class Resonance(_Secant):
    effect = RESONANCE
    signature = ("a compliant coupling: the load the encoder does not see swings against "
                 "the motor at the coupling's natural frequency")
    smooths_readings = True
    reprofile = True

    #: damping ratios and load fractions of the search
    ZETAS = (0.03, 0.1, 0.3)
    FRACTIONS = (0.3, 0.6, 0.85)

    def frequencies(self, ctx: Context) -> np.ndarray | None:
        """Natural frequencies searched [Hz]: 5 Hz to 0.8 of the filter's cut-off."""
        top = 0.8 * ctx.sig.cutoff_hz
        return None if top <= 5.0 else np.geomspace(5.0, top, 14)

    def grid(self, ctx: Context) -> np.ndarray | None:
        """First stage: every frequency at a middle damping and load fraction.

        Every point costs a simulation of the load along the whole record, so the
        search goes by stages (:meth:`next_grid`): the frequencies, then damping and
        load fraction at the best three, then a local search around the best point
        (40 to 140 simulations, 60-80 typically, where the full product of the three
        grids and its refinement took 171).
        """
        fs = self.frequencies(ctx)
        if fs is None:
            return None
        # the local search stays within what the first grids span (and a step beyond):
        # a resonance has a light damping and lies within the filter band
        self._box = ((0.88 * fs[0], 1.13 * fs[-1]),
                     (0.6 * min(self.ZETAS), 1.6 * max(self.ZETAS)))
        return objects([(f, 0.1, 0.6) for f in fs])

    def next_grid(self, rows: list[tuple[Any, float]], grid: np.ndarray, stage: int
                  ) -> np.ndarray | None:
        """Stage 1: every damping and load fraction at the three best frequencies.
        Then a local search on the lattice of steps (frequency x0.94 or /0.94, damping
        x0.6 or /0.6, load fraction +-0.12, every combination: the three interact, a
        lightly damped load answers in a narrow band and the fraction moves where the
        motor sees it): the neighbours of the best point are scored until none is
        better, at most four times."""
        def key(h: Any) -> tuple[float, ...]:
            return tuple(float(f"{v:.9g}") for v in h)

        done = {key(r[0]) for r in rows}
        best = min(rows, key=lambda r: r[1])[0]
        if stage == 1:
            top: list[float] = []
            for h, _ in sorted(rows, key=lambda r: r[1]):
                if h[0] not in top:
                    top.append(h[0])
            g = [(fq, zz, rr) for fq in top[:3] for zz in self.ZETAS for rr in self.FRACTIONS]
        elif stage <= 5:
            f, z, r = best
            g = [(f * a, z * b, float(np.clip(r + c, 0.05, 0.95)))
                 for a in (0.94, 1.0, 1 / 0.94) for b in (0.6, 1.0, 1 / 0.6)
                 for c in (-0.12, 0.0, 0.12)]
        else:
            return None
        (f_lo, f_hi), (z_lo, z_hi) = getattr(self, "_box", ((0.0, np.inf), (0.0, np.inf)))
        g = [h for h in g if key(h) not in done
             and f_lo <= h[0] <= f_hi and z_lo <= h[1] <= z_hi]
        if not g:
            return None  # the best point has every neighbour scored: a local optimum
        return objects(list(dict.fromkeys(g)))

    def prior_tol(self, h: Any, ctx: Context) -> np.ndarray | None:
        return np.full(1, 1e-6)  # the effect at h exactly: its parameters come from the grid

    def prior_center(self, h: Any, ctx: Context) -> np.ndarray | None:
        return np.ones(1)

    def effect_at(self, h: Any) -> dict[str, Any]:
        f, z, r = h
        return {"effect": RESONANCE, "frequency": float(f), "damping_ratio": float(z),
                "load_fraction": float(r)}

    def interval_params(self, hs: list[Any], ok: np.ndarray) -> dict[str, list[float]]:
        a = np.array([list(h) for h in hs], dtype=float)
        return grid_interval({k: a[:, j] for j, k in
                               enumerate(("frequency", "damping_ratio", "load_fraction"))}, ok)

    def describe(self, h: Any, beta: np.ndarray, ctx: Context) -> str:
        f, z, r = h
        return (f"A load of {100 * r:.0f} % of the mass on a coupling of {f:.3g} Hz "
                f"(damping ratio {z:.2g}).")

    def limit(self, ctx: Context, sizes: Any) -> dict[str, Any] | None:
        g = self.grid(ctx)
        if g is None:
            return hide(self.effect, float("inf"), "Hz", "a resonance",
                        experiment="the filter band is too narrow; record faster")
        fs = sorted({h[0] for h in g})
        pts = [(f, 0.05, 0.5) for f in fs]
        # (in units of the half-mass load's force)
        sz = list(in_batches(lambda ps: sizes(self.columns_of(ps, ctx)), pts))
        hidden = [f for f, s in zip(fs, sz) if s > 1.0]
        if not hidden:
            # the load's force grows about in proportion to its share of the mass
            b = 0.5 * float(max(sz))
            return hide(self.effect, b, "load fraction",
                        f"a resonance with under {100 * b:.2g} % of the mass behind its "
                        f"coupling (lightly damped, at {fs[0]:.3g} to {fs[-1]:.3g} Hz)")
        return hide(self.effect, 0.5, "load fraction",
                    f"a resonance with half the mass on the coupling at {hidden[0]:.3g} to "
                    f"{hidden[-1]:.3g} Hz",
                    experiment=("the record's motion does not excite those frequencies; a "
                                "current chirp from 5 Hz to the drive's bandwidth at rest, or "
                                "fast reversals, would"))

    def figure(self, residual: np.ndarray, contrib: np.ndarray, ctx: Context
               ) -> dict[str, Any]:
        from scipy import signal

        m = ctx.sig.mask
        nper = int(min(m.sum(), 2048))
        f, pr = signal.welch(residual[m], fs=ctx.sig.fs, nperseg=nper)
        _, pe = signal.welch(contrib[m], fs=ctx.sig.fs, nperseg=nper)
        keep = f <= ctx.sig.cutoff_hz
        return {"x": f[keep], "xlabel": "frequency [Hz]", "residual": np.sqrt(pr[keep]),
                "effect": np.sqrt(pe[keep]), "ylabel": "force density [N/sqrt(Hz)]"}
