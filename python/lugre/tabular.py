"""Recordings from tables with named columns: a pandas DataFrame, a dict of arrays, a
NumPy structured array, or anything else that maps column names to vectors.

No table library is imported: a table is recognised by its shape (``.columns`` and
``table[name]``, ``.keys()``, or ``dtype.names``).
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from typing import Any

import numpy as np

from .columns import ColumnSpec, _is_number, _parse_columns, _terms
from .exceptions import InputError
from .recording import COLUMNS, Recording

__all__ = ["as_recording", "table_columns"]


def table_columns(table: Any) -> dict[str, Any] | None:
    """The named columns of ``table`` as ``{name: vector}``, or ``None`` when it has none.

    Accepts a mapping of names to vectors, a NumPy structured array (``dtype.names``) and
    any object with a ``columns`` attribute that can be indexed by those names (a pandas
    or polars DataFrame).
    """
    names = getattr(getattr(table, "dtype", None), "names", None)
    if names:
        return {str(n): np.asarray(table[n]) for n in names}
    if isinstance(table, Mapping):
        return {str(k): v for k, v in table.items()}
    cols = getattr(table, "columns", None)
    if cols is not None and hasattr(table, "__getitem__") and not isinstance(table, np.ndarray):
        try:
            return {str(c): _vector(table[c]) for c in list(cols)}
        except (KeyError, TypeError, IndexError):
            return None
    return None


def _vector(col: Any) -> Any:
    to_numpy = getattr(col, "to_numpy", None)
    return to_numpy() if callable(to_numpy) else col


def as_recording(obj: Any, name: str = "recording", columns: ColumnSpec = None) -> Recording:
    """Turn a recording-like object into a :class:`Recording`.

    Parameters
    ----------
    obj : Recording, str, os.PathLike or table
        A recording, the path of a recording file (:func:`lugre.io.read_recording`), or a
        table with named columns (:func:`table_columns`).
    name : str
        The argument's name, for error messages.
    columns : mapping, optional
        Column mapping as for :func:`lugre.io.read_recording` (``{"x": "pos/1000"}``).

    Raises
    ------
    InputError
        ``obj`` is none of these, or a column is missing or unusable.
    """
    if isinstance(obj, Recording):
        return obj
    if isinstance(obj, (str, bytes)) or hasattr(obj, "__fspath__"):
        from .readers import read_recording

        return read_recording(os.fsdecode(obj), columns)
    table = table_columns(obj)
    if table is None:
        raise InputError.at(
            name, f"got {type(obj).__name__}: give a lugre.Recording, the path of a "
            "recording file, or a table with named columns t, x and i or F (a pandas "
            "DataFrame, a dict of arrays, a NumPy structured array)")
    mapping = _parse_columns(columns)
    names = list(table)

    def source(want: str, expr: str) -> Any:
        terms = _terms(expr, names)
        if terms is None:
            return table[expr]
        acc: Any = 1.0
        for op, tok in terms:
            if tok in table:
                val: Any = np.asarray(table[tok], dtype=float)
            elif _is_number(tok):
                val = float(tok)
            else:
                raise InputError.at(name, f"the mapping {want}={expr} names {tok!r}, which "
                                    f"is not a column; the table has: {', '.join(names)}")
            acc = acc * val if op == "*" else acc / val
        return acc

    found: dict[str, Any] = {}
    for c in COLUMNS:
        if c in mapping:
            found[c] = source(c, mapping[c])
        elif c in table:
            found[c] = table[c]
    for want in ("t", "x"):
        if want not in found:
            raise InputError.at(name, f"the table has no column {want!r}; it has: "
                                f"{', '.join(names) or '(none)'}: rename a column or map "
                                f"one with columns={{{want!r}: '<column>'}}")
    try:
        return Recording(**found, source=f"<{type(obj).__name__}>")
    except (TypeError, ValueError) as e:
        if isinstance(e, InputError):
            raise
        raise InputError.at(name, f"a column is not numeric ({e}): give numbers") from None
