"""The effect vocabulary, declared once: every effect's name, kind, parameters with their
units, whether a model holds it once at most, the experiment that measures it and the
axis its figure is read against.

The model parser, the diagnosis's candidates, its evidence, the report and the HTML
pages take what they need from :data:`EFFECTS`; a test holds the names against the list
the compiled core exports (``lugre._core.EFFECT_NAMES``).
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["ALIASES", "COGGING", "CURRENT_LAG", "CURRENT_LIMIT", "DEADBAND", "DELAY", "DRAG",
           "DRIFT", "EFFECTS", "FORCE_RIPPLE", "GRAVITY", "INERTIA", "LOAD_FRICTION", "MASS",
           "MASS_EFFECTS", "NAMES", "OFFSET", "ONE_OF_A_KIND", "POSITION_FRICTION", "RESONANCE", "SPRING",
           "STRIBECK_SHAPE", "TIMING", "TIMING_FORMS", "Effect", "Parameter", "canonical",
           "held_kinds", "is_timing", "kind"]


#: The effect names, each spelled here once; everything else takes them from here.
COGGING = "cogging"
SPRING = "spring"
OFFSET = "offset"
POSITION_FRICTION = "position_friction"
DRIFT = "drift"
MASS = "mass"
DELAY = "delay"
CURRENT_LAG = "current_lag"
RESONANCE = "resonance"
DEADBAND = "deadband"
DRAG = "drag"
STRIBECK_SHAPE = "stribeck_shape"
GRAVITY = "gravity"
LOAD_FRICTION = "load_friction"
FORCE_RIPPLE = "force_ripple"
CURRENT_LIMIT = "current_limit"


@dataclass(frozen=True)
class Parameter:
    """One parameter of an effect: its key in the model file, its SI unit (of a linear
    axis) and the unit a page shows it in, with the factor from SI."""

    name: str
    unit: str
    shown: str | None = None
    factor: float = 1.0

    @property
    def display(self) -> tuple[str, float]:
        """The displayed unit and its factor from SI."""
        return (self.unit if self.shown is None else self.shown, self.factor)


def _m(name: str) -> Parameter:  # a position or a length, shown in millimetres
    return Parameter(name, "m", "mm", 1e3)


@dataclass(frozen=True)
class Effect:
    """One effect of the vocabulary.

    ``kind``: what the search treats as one (both timing forms are ``delay``);
    ``one_of_a_kind``: a model holds it once at most; ``additive``: the parameter that
    adds up when two of it act (a finding beside the model's own corrects it);
    ``abscissa``: ``x``, ``v`` or ``t``, what its figure is drawn against;
    ``derived``: parameters a report gives beside the file's (a lag's mean delay);
    ``adds_mass``: its ``additive`` parameter adds to the moving mass [kg].
    """

    name: str
    parameters: tuple[Parameter, ...]
    experiment: str
    abscissa: str
    kind: str = ""
    one_of_a_kind: bool = False
    additive: str | None = None
    derived: tuple[Parameter, ...] = ()
    adds_mass: bool = False

    def __post_init__(self) -> None:
        if not self.kind:
            object.__setattr__(self, "kind", self.name)

    @property
    def units(self) -> dict[str, str]:
        """SI unit of every parameter, the derived ones included."""
        return {p.name: p.unit for p in self.parameters + self.derived}

    @property
    def display(self) -> dict[str, tuple[str, float]]:
        """Displayed unit and factor of every parameter, the derived ones included."""
        return {p.name: p.display for p in self.parameters + self.derived}

    @property
    def words(self) -> str:
        """The name in words ("position friction")."""
        return self.name.replace("_", " ")


#: The kind of both timing forms.
TIMING = DELAY

_TIMING_EXPERIMENT = "fast reversals or a current chirp up to a few hundred Hz"

#: The vocabulary, in the order of the CONTRACT (and of the core's ``EFFECT_NAMES``).
EFFECTS: dict[str, Effect] = {e.name: e for e in (
    Effect(COGGING, (Parameter("amplitude", "N"), _m("pitch"), Parameter("phase", "rad")),
           "a slow constant-speed move over at least three pitches in each direction", "x"),
    Effect(SPRING, (Parameter("stiffness", "N/m"), _m("x0")),
           "slow moves across the whole stroke in both directions", "x"),
    Effect(OFFSET, (Parameter("force", "N"),),
           "constant-speed moves in both directions at the same speed", "v",
           additive="force"),
    Effect(POSITION_FRICTION, (_m("positions"), Parameter("scale", "")),
           "slow constant-speed moves over the whole stroke in both directions", "x"),
    Effect(DRIFT, (Parameter("gain", ""), Parameter("time_constant", "s")),
           "a recording from a cold start lasting several time constants", "t"),
    Effect(MASS, (Parameter("delta", "kg"),),
           "fast back-and-forth moves (large accelerations)", "t", additive="delta",
           adds_mass=True),
    Effect(TIMING, (Parameter("seconds", "s", "ms", 1e3),), _TIMING_EXPERIMENT, "t",
           one_of_a_kind=True, derived=(Parameter("bandwidth", "Hz"),)),
    Effect(CURRENT_LAG, (Parameter("bandwidth", "Hz"),), _TIMING_EXPERIMENT, "t",
           kind=TIMING, one_of_a_kind=True,
           derived=(Parameter("seconds", "s", "ms", 1e3),)),
    Effect(RESONANCE, (Parameter("frequency", "Hz"), Parameter("damping_ratio", ""),
                         Parameter("load_fraction", "")),
           "a chirp of the position reference through the suspected frequency band", "t",
           one_of_a_kind=True),
    Effect(DEADBAND, (Parameter("current", "A"),),
           "very slow moves that cross zero current", "v"),
    Effect(DRAG, (Parameter("coefficient", "N s^2/m^2", "N s²/m²"),),
           "constant-speed moves at several high speeds", "v", additive="coefficient"),
    Effect(STRIBECK_SHAPE, (Parameter("exponent", ""),),
           "slow feeds at speeds from a tenth to ten times the Stribeck velocity", "v",
           one_of_a_kind=True),
    # (rotary axes only: the torque [N m] is written in a linear axis's unit, "N", as
    # every unit here; lugre.units speaks it as N m on a rotary axis)
    Effect(GRAVITY, (Parameter("torque", "N"), Parameter("phase", "rad")),
           "slow constant-speed moves over a whole turn, or the joint's whole swing, in "
           "both directions", "x", one_of_a_kind=True),
    Effect(LOAD_FRICTION, (Parameter("coefficient", ""),),
           "moves in both directions at the same speeds under light and heavy loads (a "
           "payload, or hard accelerations beside slow feeds)", "v", one_of_a_kind=True),
    Effect(FORCE_RIPPLE, (Parameter("amplitude", ""), _m("pitch"), Parameter("phase", "rad")),
           "constant-speed moves over at least three pitches in each direction, at two "
           "different forces (a payload or an incline: cogging stays, ripple scales)", "x"),
    Effect(CURRENT_LIMIT, (Parameter("current", "A"),),
           "fast moves or steps that ask the amplifier for more current than it gives",
           "t", one_of_a_kind=True),
)}

#: Every effect name, in the vocabulary's order.
NAMES: tuple[str, ...] = tuple(EFFECTS)

#: Effects that add to the moving mass (by their ``additive`` parameter).
MASS_EFFECTS: tuple[str, ...] = tuple(n for n, e in EFFECTS.items() if e.adds_mass)

#: The forms of the timing kind: a pure delay, a first-order current lag.
TIMING_FORMS: tuple[str, ...] = tuple(n for n, e in EFFECTS.items() if e.kind == TIMING)

#: Kinds a model holds once at most (the timing kind is ``delay``, for both forms).
ONE_OF_A_KIND: tuple[str, ...] = tuple(dict.fromkeys(
    e.kind for e in EFFECTS.values() if e.one_of_a_kind))


#: Other names the model file may give an effect: a rotary axis's ``mass`` effect is
#: written ``inertia`` (CONTRACT, "Rotary axes").
INERTIA = "inertia"
ALIASES: dict[str, str] = {INERTIA: MASS}


def canonical(effect: str) -> str:
    """The vocabulary's name of an effect written under another name (``inertia``)."""
    return ALIASES.get(effect, effect)


def kind(effect: str) -> str:
    """An effect's kind: its name, but ``delay`` for both timing forms."""
    e = EFFECTS.get(str(effect))
    return e.kind if e is not None else str(effect)


def is_timing(effect: str) -> bool:
    """Whether an effect is a timing term (a delay or a current lag, one kind)."""
    return kind(effect) == TIMING


def held_kinds(effects: list[dict[str, object]]) -> set[str]:
    """The one-of-a-kind kinds a model's ``effects`` already hold (no room for another)."""
    return {kind(str(e["effect"])) for e in effects} & set(ONE_OF_A_KIND)
