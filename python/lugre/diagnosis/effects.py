"""The candidates of the vocabulary (:mod:`lugre.diagnosis.candidates`), under their
former module name."""

from .candidates import *
from .candidates import __all__  # noqa: F401
