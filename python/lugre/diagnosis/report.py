"""The result of a diagnosis: findings, fit figures, residuals; REPORT.json and a summary."""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .. import units as U
from .._words import plain_text
from ..model import Model
from ..units import axis_units
from ..vocabulary import INERTIA, MASS, is_timing
from .candidates.lag import timing_words

__all__ = ["Diagnosis", "Finding"]


@dataclass
class Finding:
    """One effect the model left out.

    Attributes
    ----------
    effect : str
        Vocabulary name (``cogging``, ``offset``, ...).
    parameters : dict
        The effect's parameters (CONTRACT form, without ``"effect"``).
    where : dict
        ``position``, ``time``, ``velocity``: ``[lo, hi]`` or ``None`` (not confined).
    explained : float
        Share of the residual variance (of the model as given) it accounts for.
    evidence : str
        One or two sentences a person can check.
    alternatives : list of dict
        Explanations that fit equally well, with the experiment that separates them.
    uncertainty : dict
        What the record determines of the parameters (intervals; for ``drift`` the
        time constant, the gain, the initial rate and the change over the record).
    """

    effect: str
    parameters: dict[str, Any]
    where: dict[str, Any]
    explained: float
    evidence: str
    alternatives: list[dict[str, Any]] = field(default_factory=list)
    uncertainty: dict[str, Any] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        """The CONTRACT form (plus ``alternatives`` when there are any)."""
        d: dict[str, Any] = {
            "effect": self.effect,
            "parameters": _plain(self.parameters),
            "where": _plain(self.where),
            "explained": round(float(self.explained), 4),
            "evidence": self.evidence,
        }
        if self.alternatives:
            d["alternatives"] = _plain(self.alternatives)
        if self.uncertainty:
            d["uncertainty"] = _plain(self.uncertainty)
        return d


def _plain(o: Any) -> Any:
    if isinstance(o, dict):
        return {str(k): _plain(v) for k, v in o.items()}
    if isinstance(o, (list, tuple)):
        return [_plain(v) for v in o]
    if isinstance(o, (np.floating, float)):
        f = float(o)
        return f if math.isfinite(f) else None
    if isinstance(o, (np.integer,)):
        return int(o)
    if isinstance(o, np.ndarray):
        return _plain(o.tolist())
    return o


@dataclass
class Diagnosis:
    """What :func:`lugre.diagnosis.diagnose` found.

    Attributes
    ----------
    findings : list of Finding
        Most important first; empty when nothing beyond noise was found.
    fit : dict
        ``before``/``after`` (and ``holdout_before``/``holdout_after`` when a hold-out
        recording was given, ``closed_loop`` when the controller is known, ``held_out``
        for the held-out blocks of the recording itself): ``rms_force`` [N] and
        ``nrmse_force``.
    model : Model
        The model as given.
    augmented : Model
        With the findings added and the base parameters re-estimated.
    base : dict
        Per base parameter: ``before``, ``after``, ``change`` (relative), ``tolerance``.
    noise : dict
        Noise floor: ``rms`` [N], ``n_eff``, ``bandwidth_hz``.
    located : dict
        Where the residual rises above the noise floor, before and after.
    unexplained : dict or None
        Set when the residual stays clearly above noise and no effect explains it.
    notes : list of str
        Further remarks (poorly determined parameters, ambiguities).
    trials : list of dict
        Every candidate tried, with its held-out evidence.
    data : dict
        Arrays for plots: ``t``, ``x``, ``v``, ``before``, ``after``, ``force``, and the
        position spectrum of the residual ``spectrum_k``/``spectrum_p``.
    """

    findings: list[Finding]
    fit: dict[str, Any]
    model: Model
    augmented: Model
    base: dict[str, dict[str, float]]
    noise: dict[str, float]
    located: dict[str, Any]
    unexplained: dict[str, Any] | None = None
    notes: list[str] = field(default_factory=list)
    trials: list[dict[str, Any]] = field(default_factory=list)
    data: dict[str, Any] = field(default_factory=dict, repr=False)
    timing: float = 0.0
    #: per effect not found, the smallest size this record would have revealed
    could_not_reveal: list[dict[str, Any]] = field(default_factory=list)
    #: base parameters that moved by more than two tolerances, in words
    base_moves: list[dict[str, Any]] = field(default_factory=list)
    #: the verdict in one paragraph
    verdict: str = ""
    #: effects consistent on the held-out blocks but under 0.3 % of the motor force:
    #: kept in the augmented model (so that they do not leak into the findings), not
    #: named; each ``effect``, ``parameters``, ``rms_force`` [N]
    minor: list[dict[str, Any]] = field(default_factory=list)
    #: effects of the model as given that the record contradicts: left out of the
    #: augmented model; each ``effect``, ``parameters``, ``evidence`` and the block test
    removed: list[dict[str, Any]] = field(default_factory=list)
    #: set when the base as given was far from what the record supports and the search
    #: ran from the refitted base: ``moves`` (``name``, ``given``, ``refit``, ``change``),
    #: ``rms_given``, ``rms_refit`` [N], ``text``
    rebased: dict[str, Any] | None = None

    def augmented_model(self) -> Model:
        """The model with the findings added to ``effects`` and the base re-estimated."""
        return self.augmented

    def to_dict(self) -> dict[str, Any]:
        """REPORT.json (CONTRACT shape, plus ``noise``, ``base``, ``located``, ...);
        ``axis`` says the kind of axis and the units of its numbers."""
        d: dict[str, Any] = {
            "axis": axis_units(self.model.kind),
            "verdict": self.verdict,
            "findings": [f.to_dict() for f in self.findings],
            "fit": _plain(self.fit),
            "noise": _plain(self.noise),
            "base": _plain(self.base),
            "located": _plain(self.located),
            "unexplained": _plain(self.unexplained),
            "notes": list(self.notes),
            "base_moves": _plain(self.base_moves),
            "could_not_reveal": _plain(self.could_not_reveal),
            "minor": _plain(self.minor),
            "removed": _plain(self.removed),
            "rebased": _plain(self.rebased),
            "trials": [
                {k: _plain(v) for k, v in t.items() if k in (
                    "step", "effect", "gain", "t", "p", "positive", "blocks", "ratio",
                    "contrib", "accepted", "why")}
                for t in self.trials
            ],
        }
        return self._rotary_names(d)

    def _rotary_names(self, d: dict[str, Any]) -> dict[str, Any]:
        """A rotary axis's report writes the ``mass`` effect ``inertia`` (CONTRACT)."""
        if not self.model.is_rotary:
            return d
        for key in ("findings", "minor", "removed"):
            for e in d.get(key) or []:
                if e.get("effect") == MASS:
                    e["effect"] = INERTIA
        return d

    def to_json(self, indent: int | None = 2) -> str:
        """:meth:`to_dict` as JSON text."""
        return json.dumps(self.to_dict(), indent=indent)

    def summary(self) -> str:
        """A plain-text report for a control engineer, in the axis's units."""
        with U.axis(self.model.kind):
            return self._summary()

    def _residual_lines(self) -> list[str]:
        """The noise floor and the residual before and after the findings, in the
        axis's units."""
        fb, fa = self.fit["before"], self.fit["after"]
        n, after = U.si("N"), self.noise.get("rms_after")
        # the floor is read on the base refit's residual; findings that spread over the
        # band (a lag's) can lower it a great deal, and then both are said
        floor = (f"Noise floor {self.noise['rms']:.3g} {n} rms before the findings, "
                 f"{after:.3g} {n} after" if after is not None and after < 0.5 * self.noise["rms"]
                 else f"Noise floor {self.noise['rms']:.3g} {n} rms")
        lines = [(f"{floor} (n_eff {self.noise['n_eff']:.0f}). "
                  f"{U.force_words().capitalize()} residual {fb['rms_force']:.3g} {n} -> "
                  f"{fa['rms_force']:.3g} {n} (nrmse {100 * fb['nrmse_force']:.2f} % -> "
                  f"{100 * fa['nrmse_force']:.2f} %).")]
        if self.fit.get("holdout_before"):
            hb, ha = self.fit["holdout_before"], self.fit["holdout_after"]
            lines.append(
                f"Hold-out: {hb['rms_force']:.3g} {n} -> {ha['rms_force']:.3g} {n} "
                f"(nrmse {100 * hb['nrmse_force']:.2f} % -> {100 * ha['nrmse_force']:.2f} %)."
            )
        if "closed_loop" in self.fit:
            cl = self.fit["closed_loop"]
            lines.append(
                "Closed loop (simulated under the controller vs measured): position "
                f"{U.micro(cl['before']['rms_position'])} -> "
                f"{U.micro(cl['after']['rms_position'])} rms, current "
                f"{cl['before']['rms_current']:.3g} A -> {cl['after']['rms_current']:.3g} A rms."
            )
        return lines

    def _summary(self) -> str:
        from .evidence import effect_words

        lines: list[str] = [self.verdict] if self.verdict else []
        lines += self._residual_lines()
        if self.rebased:
            lines.append(f"Base refitted: {self.rebased['text']}.")
        for r in self.removed:
            what = "Replaced in the model" if r.get("replaced") else "Removed from the model"
            lines.append(f"{what}: {U.words(r['effect'])}. {plain_text(r['evidence'])}")
        if not self.findings:
            lines.append("Findings: none beyond noise.")
        for k, f in enumerate(self.findings, 1):
            if is_timing(f.effect):
                ps = timing_words(f.effect, f.parameters)
            else:
                ps = ", ".join(
                    f"{a} {U.fmt(v, U.unit_of(f.effect, a))}" for a, v in f.parameters.items()
                    if a not in ("positions", "scale")
                )
            wh = ", ".join(f"{a} {U.fmt_range(v[0], v[1], U.where_unit(a))}"
                           if isinstance(v, (list, tuple)) and len(v) == 2 else f"{a} {_fmt(v)}"
                           for a, v in f.where.items() if v is not None)
            line = (f"{k}. {U.words(f.effect)}{' (' + ps + ')' if ps else ''} explains "
                    f"{U.percent(f.explained)} of "
                    f"the residual{'; lives at ' + wh if wh else ''}.")
            lines.append(line.replace("\u2212", "-"))
            lines.append(f"   {plain_text(f.evidence)}")
            for alt in f.alternatives:
                ap = alt.get("parameters") or {}
                if is_timing(str(alt["effect"])):
                    ap_txt = "(" + timing_words(alt["effect"], {
                        **ap, "seconds": alt.get("effective_delay_s", ap.get("seconds"))}) + ")"
                else:
                    ap_txt = _fmt(ap)
                lines.append(U.words(f"   Equally well: {alt['effect']} {ap_txt}. "
                                     f"To separate: {alt['experiment']}"))
        if self.minor:
            lines.append(
                "Minor corrections, consistent on the held-out stretches but each under "
                f"0.3 % of the motor {U.force_words()} (kept in the augmented model, too "
                "small to name): "
                + "; ".join(f"{U.words(m['effect'])} "
                            f"({effect_words(m['effect'], m['parameters'])}; "
                            f"{m['rms_force']:.2g} {U.si('N')} rms)" for m in self.minor) + ".")
        moved = [f"{U.words(n)} {100 * b['change']:+.1f} %" for n, b in self.base.items()
                 if abs(b["change"]) > 0.005]
        if moved:
            lines.append("Base parameters re-estimated: " + ", ".join(moved) + ".")
        if self.could_not_reveal:
            lines.append("What this record could have hidden: " + "; ".join(
                h["text"] + (f" ({h['experiment']})" if h.get("experiment") else "")
                for h in self.could_not_reveal) + ".")
        if self.unexplained:
            u = self.unexplained
            lines.append(f"Unexplained: {u['message']}")
        lines.extend(U.words(n) for n in self.notes)
        return "\n".join(lines)


def _fmt(v: Any) -> str:
    if isinstance(v, float):
        return f"{v:.4g}"
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_fmt(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{k}: {_fmt(x)}" for k, x in v.items()) + "}"
    return str(v)
