"""Mismatch diagnosis: locate where a model misses a recording, name the missing physics
(in the effects vocabulary of CONTRACT.md), fit it jointly with the base parameters, and
show the fit improve.

>>> import lugre
>>> from lugre.diagnosis import diagnose, write_plots
>>> d = diagnose(lugre.read_recording("rec.csv"), lugre.load_model("m.json"))  # doctest: +SKIP
>>> print(d.summary())                                                        # doctest: +SKIP
"""

from __future__ import annotations

from .chain import fit_model
from .core import diagnose, evaluate
from .inverse import fit_inverse_dynamics
from .locate import locate
from .plots import write_plots
from .report import Diagnosis, Finding

__all__ = ["Diagnosis", "Finding", "diagnose", "evaluate", "fit_inverse_dynamics", "fit_model", "locate",
           "write_plots"]
