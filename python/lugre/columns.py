"""Column mappings and column expressions: where a file keeps each recording column.

``{"x": "qm"}`` or ``"x=qm,F=gtau*vir"``: a source is a column name, or a product or
quotient of columns, scalars stored in the file and numbers (``x=pos_mm/1000``).
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Mapping
from typing import Union

from .exceptions import FileFormatError, InputError
from .recording import _DESCRIPTION, COLUMNS

__all__ = ["ColumnSpec", "parse_columns"]

#: Names of a scalar sample time that let a ``.mat``/``.npz`` file without ``t`` be read.
_SAMPLE_TIME_NAMES = ("dt", "Ts", "ts", "Te", "te", "T_s", "sample_time", "h")

#: Usual other names of each column, for the suggestion in "missing column" errors.
_GUESSES: dict[str, tuple[str, ...]] = {
    "t": ("time", "t_s", "timestamp", "tm"),
    "x": ("qm", "pos", "position", "q", "x_m", "xm", "p"),
    "i": ("current", "iq", "i_q", "ia", "cur", "i_cmd", "ic"),
    "F": ("force", "f", "fm", "u", "tau", "torque"),
    "v": ("vel", "velocity", "qd", "dq", "speed", "v_m", "vm"),
    "x_ref": ("qg", "xr", "xref", "x_d", "xd", "pos_ref", "ref", "r"),
    "v_ref": ("vr", "vref", "v_d", "vd", "vel_ref", "speed_ref"),
}

ColumnSpec = Union[Mapping[str, str], Iterable[str], str, None]


def _parse_columns(columns: ColumnSpec) -> dict[str, str]:
    """Normalise a column mapping to ``{canonical: source expression}``."""
    if columns is None:
        return {}
    if isinstance(columns, Mapping):
        items = list(columns.items())
    else:
        if isinstance(columns, str):
            columns = [c for c in columns.split(",") if c.strip()]
        items = []
        for spec in columns:
            if not isinstance(spec, str) or "=" not in spec:
                raise InputError.at(
                    "columns", f"mapping {spec!r} is not of the form 'name=source': "
                    "write e.g. 'x=qm' or 'F=gtau*vir'"
                )
            k, _, val = spec.partition("=")
            items.append((k, val))
    out: dict[str, str] = {}
    for k, val in items:
        k, val = str(k).strip(), str(val).strip()
        if k not in COLUMNS:
            raise InputError.at(
                "columns", f"mapping names {k!r}, which is not a recording column: "
                f"use {', '.join(COLUMNS)}"
            )
        if not val:
            raise InputError.at("columns", f"mapping for {k!r} is empty: give a source "
                                "such as '{k}=<column>'")
        out[k] = val
    return out


_TOKEN = re.compile(r"\s*([*/])\s*")


def _terms(expr: str, names: Iterable[str]) -> list[tuple[str, str]] | None:
    """Split ``a*b/c`` into ``[("*", "a"), ("*", "b"), ("/", "c")]``; ``None`` when
    ``expr`` is a plain column name."""
    if expr in names:
        return None
    parts = _TOKEN.split(expr)
    terms = [("*", parts[0].strip())]
    for op, tok in zip(parts[1::2], parts[2::2]):
        terms.append((op, tok.strip()))
    return terms


def _is_number(s: str) -> bool:
    try:
        float(s)
    except ValueError:
        return False
    return True


def _missing(
    path: str,
    want: str,
    found: Iterable[str],
    mapped: str | None,
    candidates: Iterable[str] | None = None,
) -> FileFormatError:
    found = list(found)
    listing = ", ".join(found) if found else "(none)"
    if mapped is not None:
        msg = (
            f"{path}: the column mapping gives {want}={mapped}, but the file has no "
            f"column {mapped!r}; it has: {listing}"
        )
    else:
        lower = {c.lower(): c for c in (candidates if candidates is not None else found)}
        example = next((lower[g] for g in _GUESSES[want] if g in lower), "<column>")
        msg = (
            f"{path}: no column {want!r} ({_DESCRIPTION[want]}); the file has: {listing}. "
            f"Map one with columns={{{want!r}: {example!r}}} (or '{want}={example}' on "
            "the command line)"
        )
    return FileFormatError(msg, path=path, column=want)


parse_columns = _parse_columns
