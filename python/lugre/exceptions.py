"""Exceptions and warnings raised by :mod:`lugre`.

Every error is a :class:`LugreError` *and* the builtin a caller would expect
(``ValueError``), so ``except ValueError`` keeps working while ``except LugreError``
catches everything the package raises on purpose. The Rust core maps its single error
enum onto these classes one to one:

=====================  ==========================================================
Rust ``Error``         Python class
=====================  ==========================================================
``Parameter``          :class:`ParameterError` (``name``, ``value``, ``requirement``)
``Model``              :class:`ModelError` (``path``)
``Input``              :class:`InputError` (``name``)
``Data``               :class:`DataError`
=====================  ==========================================================

:class:`FileFormatError` is raised by the Python readers of recordings
(:mod:`lugre.io`); it names the file, and where it applies the row and column.

Warnings subclass :class:`LugreWarning` (a ``UserWarning``) so they can be filtered as
a group, for example ``warnings.simplefilter("error", lugre.exceptions.LugreWarning)``.
"""

from __future__ import annotations

import math
from decimal import Decimal
from typing import Any

__all__ = [
    "ConvergenceWarning",
    "DataError",
    "FileFormatError",
    "IdentifiabilityWarning",
    "InputError",
    "LugreError",
    "LugreWarning",
    "ModelError",
    "ParameterError",
    "PassivityWarning",
    "UnitsWarning",
]


def _fmt_f64(x: Any) -> str:
    """Format a number as Rust's ``Display`` for ``f64`` does (``0``, ``-0.01``, ``NaN``,
    ``inf``, ``0.0000001``), so that messages match the core's; other values by ``str``."""
    if isinstance(x, bool) or not isinstance(x, (int, float)):
        return str(x)
    x = float(x)
    if math.isnan(x):
        return "NaN"
    if math.isinf(x):
        return "inf" if x > 0 else "-inf"
    s = repr(x)
    if "e" in s or "E" in s:
        s = format(Decimal(s), "f")
    return s.removesuffix(".0")


class LugreError(Exception):
    """Base class of every error raised on purpose by :mod:`lugre`."""


class _Detailed(LugreError):
    """Shared machinery: a message plus keyword attributes that survive pickling."""

    _fields: tuple[str, ...] = ()

    def __init__(self, message: str, **fields: Any) -> None:
        super().__init__(message)
        unknown = set(fields) - set(self._fields)
        if unknown:
            raise TypeError(
                f"{type(self).__name__}() got unexpected keyword(s) {sorted(unknown)}"
            )
        for f in self._fields:
            setattr(self, f, fields.get(f))

    def __reduce__(self) -> tuple[Any, ...]:
        fields = {f: getattr(self, f, None) for f in self._fields}
        return (_rebuild, (type(self), self.args, fields))


def _rebuild(cls: type[_Detailed], args: tuple[Any, ...], fields: dict[str, Any]) -> Any:
    """Unpickle a :class:`_Detailed` error with its attributes."""
    return cls(*args, **fields)


class ParameterError(_Detailed, ValueError):
    """A model parameter or option is out of range.

    Parameters
    ----------
    message : str
        The full message, e.g. ``"parameter friction.negative.vs = -0.01 is invalid:
        it must be greater than zero"``.
    name : str, optional
        Path of the parameter, e.g. ``"friction.negative.vs"`` or ``"substeps"``.
    value : float, optional
        The offending value.
    requirement : str, optional
        What the value must satisfy.

    Examples
    --------
    >>> e = ParameterError.invalid("axis.mass", 0.0, "must be greater than zero")
    >>> str(e)
    'parameter axis.mass = 0 is invalid: it must be greater than zero'
    >>> isinstance(e, ValueError), e.name
    (True, 'axis.mass')
    """

    _fields = ("name", "value", "requirement")
    name: str | None
    value: Any
    requirement: str | None

    @classmethod
    def invalid(cls, name: str, value: Any, requirement: str) -> ParameterError:
        """Build the error with the core's standard message.

        Parameters
        ----------
        name : str
            Path of the parameter.
        value : object
            The offending value.
        requirement : str
            What it must satisfy (a phrase following "it").

        Returns
        -------
        ParameterError
        """
        return cls(
            f"parameter {name} = {_fmt_f64(value)} is invalid: it {requirement}",
            name=name,
            value=value,
            requirement=requirement,
        )


class ModelError(_Detailed, ValueError):
    """The model description is malformed (missing key, wrong type, unknown effect).

    Parameters
    ----------
    message : str
        The full message, starting with ``"model: <path>: "``.
    path : str, optional
        Where in the model, e.g. ``"effects[2].pitch"``.
    """

    _fields = ("path",)
    path: str | None

    @classmethod
    def at(cls, path: str, message: str) -> ModelError:
        """Build the error with the core's standard message ``model: {path}: {message}``.

        Parameters
        ----------
        path : str
            Where in the model.
        message : str
            What is wrong and how to fix it.

        Returns
        -------
        ModelError
        """
        return cls(f"model: {path}: {message}", path=path)


class InputError(_Detailed, ValueError):
    """An input array is unusable (NaN or inf, lengths differ, empty, time not increasing).

    Parameters
    ----------
    message : str
        The full message, starting with ``"input <name>: "``.
    name : str, optional
        The argument, e.g. ``"t"`` or ``"x_ref"``.
    """

    _fields = ("name",)
    name: str | None

    @classmethod
    def at(cls, name: str, message: str) -> InputError:
        """Build the error with the core's standard message ``input {name}: {message}``.

        Parameters
        ----------
        name : str
            The argument.
        message : str
            What is wrong and how to fix it.

        Returns
        -------
        InputError
        """
        return cls(f"input {name}: {message}", name=name)


class DataError(LugreError, ValueError):
    """The data cannot support the requested estimate (or a simulation diverged)."""


class FileFormatError(_Detailed, ValueError):
    """A recording or model file cannot be read.

    The message names the file and, where it applies, the row (1-based line number in
    the file) and the column, and says how to fix it.

    Parameters
    ----------
    message : str
        The full message.
    path : str, optional
        The file.
    row : int, optional
        1-based line number in the file.
    column : str, optional
        Column name.
    """

    _fields = ("path", "row", "column")
    path: str | None
    row: int | None
    column: str | None


class LugreWarning(UserWarning):
    """Base class of the warnings issued by :mod:`lugre`."""


class PassivityWarning(LugreWarning):
    """sigma1 exceeds the passivity bound ``4*sigma2*fc/(fs - fc)`` (Barabanov & Ortega 2000)."""


class IdentifiabilityWarning(LugreWarning):
    """The data determine a parameter poorly (flat objective, strong correlation)."""


class ConvergenceWarning(LugreWarning):
    """An iterative estimate stopped at its iteration limit before converging."""


class UnitsWarning(LugreWarning):
    """Values look like they are in the wrong units (mm for m, ms for s, ...)."""
