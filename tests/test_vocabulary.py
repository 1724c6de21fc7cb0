"""The effect vocabulary is declared once: the registry, the core's list, the
diagnosis's candidates and the model parser agree."""

from __future__ import annotations

import lugre
import pytest
from lugre import _core
from lugre.diagnosis.candidates import candidates
from lugre.vocabulary import (
    EFFECTS,
    FORCE_RIPPLE,
    GRAVITY,
    NAMES,
    ONE_OF_A_KIND,
    held_kinds,
    is_timing,
    kind,
)


def test_the_registry_names_what_the_core_simulates():
    assert NAMES == tuple(_core.EFFECT_NAMES)


def test_every_kind_has_one_candidate_and_every_candidate_a_kind():
    """On a rotary axis every kind; on a linear one every kind but gravity (a linear
    axis's weight is an offset, and the model refuses a gravity on it)."""
    kinds = {kind(n) for n in NAMES}
    effects = [c.effect for c in candidates("rotary")]
    assert len(effects) == len(set(effects))
    assert set(effects) == kinds
    assert {c.effect for c in candidates()} == kinds - {"gravity"}


def test_one_of_a_kind_and_timing():
    assert set(ONE_OF_A_KIND) <= {kind(n) for n in NAMES}
    timing = [n for n in NAMES if is_timing(n)]
    assert len(timing) == 2 and len({kind(n) for n in timing}) == 1
    assert [c.effect for c in candidates() if c.timing] == [kind(timing[0])]
    model = [{"effect": n} for n in NAMES]
    assert held_kinds(model) == set(ONE_OF_A_KIND)


def test_every_parameter_has_a_unit_and_every_effect_an_experiment():
    for spec in EFFECTS.values():
        assert spec.experiment and spec.abscissa in ("x", "v", "t")
        for p in spec.parameters + spec.derived:
            assert p.unit in _SI, (spec.name, p.name, p.unit)
        if spec.additive is not None:
            assert spec.additive in spec.units


def test_the_parser_accepts_every_name_and_rejects_others():
    base = lugre.Model.paper().to_dict()
    rotary = {**base, "axis": {"kind": "rotary", "inertia": 0.5, "torque_constant": 2.0}}
    for n in NAMES:
        eff = {"effect": n, **{p.name: _value(n, p.name) for p in EFFECTS[n].parameters}}
        lugre.Model.from_dict({**rotary, "effects": [eff]})
        if n == GRAVITY:  # a linear axis's weight is an offset
            with pytest.raises(lugre.ModelError, match="rotary axes only") as e:
                lugre.Model.from_dict({**base, "effects": [eff]})
            assert e.value.path == "effects[0].effect" and "offset" in str(e.value)
        else:
            lugre.Model.from_dict({**base, "effects": [eff]})
    with pytest.raises(lugre.ModelError, match="unknown effect"):
        lugre.Model.from_dict({**base, "effects": [{"effect": "backlash"}]})


#: The SI units a linear axis's effect parameters may have.
_SI = {"", "N", "m", "rad", "N/m", "s", "kg", "Hz", "A", "N s^2/m^2"}


def _value(effect: str, name: str) -> object:
    if name == "positions":
        return [0.0, 0.1]
    if name == "scale":
        return [1.0, 1.1]
    if effect == FORCE_RIPPLE and name == "amplitude":  # a share, below 1
        return 0.5
    return 0.5 if name in ("load_fraction", "gain") else 1.0
