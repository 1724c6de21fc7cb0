"""Readers and writers of recordings and steady-state points (CSV, ``.npz``, ``.mat``, and
through :mod:`lugre.columnar` ``.parquet`` and ``.h5``).

CSV files may start with ``#`` lines (``# key: value`` lines become
:attr:`~lugre.recording.Recording.meta`), then one header line, then comma-separated
numbers. Files with other names are read through a column mapping
(:mod:`lugre.columns`); for the EMPS benchmark (``DATA_EMPS.mat``: ``qm``, ``qg``,
``vir`` [V], ``gtau`` [N/V], ``t``)::

    rec = read_recording("DATA_EMPS.mat", columns={"x": "qm", "x_ref": "qg",
                                                   "F": "gtau*vir"})

Every problem with a file raises :class:`~lugre.exceptions.FileFormatError` naming the
file, the row (the 1-based line number for CSV, the sample index otherwise) and the
column, and saying how to fix it. Writers replace the destination atomically: the
file is written whole or not at all.
"""

from __future__ import annotations

import io as _io
import json
import math
import os
from pathlib import Path
from typing import Any, Callable

import numpy as np

from ._atomic import atomic_write as _atomic_write
from .columnar import COLUMNAR_SUFFIXES, read_columnar, write_columnar
from .columns import _SAMPLE_TIME_NAMES, ColumnSpec, _is_number, _missing, _parse_columns, _terms
from .exceptions import FileFormatError, InputError
from .recording import COLUMNS, Recording

__all__ = ["MAX_MAGNITUDE", "ROTARY_X_UNITS", "X_UNITS", "is_points_file", "read_points", "read_recording", "write_recording"]

def _read_csv_table(path: str) -> tuple[dict[str, str], list[str], list[tuple[int, list[str]]]]:
    """Metadata, header and data rows (with their 1-based line numbers) of a CSV file."""
    meta: dict[str, str] = {}
    header: list[str] | None = None
    rows: list[tuple[int, list[str]]] = []
    if not os.path.exists(path):
        raise FileNotFoundError(2, f"recording {path!r} does not exist", path)
    with open(path, encoding="utf-8-sig", newline="") as fh:
        try:
            for lineno, line in enumerate(fh, start=1):
                s = line.strip()
                if not s:
                    continue
                if s.startswith("#"):
                    if header is None:
                        key, sep, val = s[1:].partition(":")
                        if sep and 0 < len(key.strip()) <= 40:
                            meta[key.strip()] = val.strip()
                    continue
                cells = [c.strip().strip('"').strip() for c in s.split(",")]
                if header is None:
                    _separator_hint(path, lineno, s, cells)
                    header = cells
                    seen: set[str] = set()
                    for c in header:
                        if not c:
                            raise FileFormatError(
                                f"{path}, line {lineno}: the header has an empty column "
                                "name: name every column",
                                path=path, row=lineno,
                            )
                        if c in seen:
                            raise FileFormatError(
                                f"{path}, line {lineno}: the header names column {c!r} "
                                "twice: rename one",
                                path=path, row=lineno, column=c,
                            )
                        seen.add(c)
                    continue
                if len(cells) != len(header):
                    _separator_hint(path, lineno, s, cells)
                    raise FileFormatError(
                        f"{path}, line {lineno}: {len(cells)} values for the "
                        f"{len(header)} columns of the header ({', '.join(header)}): "
                        "give one value per column, separated by commas",
                        path=path, row=lineno,
                    )
                rows.append((lineno, cells))
        except UnicodeDecodeError as e:
            raise FileFormatError(
                f"{path}: not a text file ({e}); recordings are UTF-8 CSV, .npz or .mat",
                path=path,
            ) from None
    if header is None:
        raise FileFormatError(
            f"{path}: no header line: after the optional '#' lines give a line of column "
            "names such as 't,x,i'",
            path=path,
        )
    if not rows:
        raise FileFormatError(
            f"{path}: no data rows after the header: give at least one sample", path=path
        )
    return meta, header, rows


def _separator_hint(path: str, lineno: int, line: str, cells: list[str]) -> None:
    """Refuse a line separated by ``;`` or tabs with the fix, instead of one wide column."""
    for sep, name in ((";", "semicolons"), ("\t", "tabs")):
        if sep in line and len(cells) <= 2 and line.count(sep) >= 1:
            raise FileFormatError(
                f"{path}, line {lineno}: the values are separated by {name}; recordings "
                "are comma-separated: replace each separator with ',' (and a decimal "
                "comma with '.'), e.g. save as 'CSV (comma delimited)'",
                path=path, row=lineno,
            )


def _csv_column(path: str, header: list[str], rows: list[tuple[int, list[str]]],
                name: str) -> np.ndarray:
    j = header.index(name)
    out = np.empty(len(rows))
    for r, (lineno, cells) in enumerate(rows):
        cell = cells[j]
        try:
            out[r] = float(cell)
        except ValueError:
            raise FileFormatError(
                f"{path}, line {lineno}, column {name!r}: {cell!r} is not a number: "
                "fix or remove the row (numbers use '.' as decimal point, cells are "
                "separated by ',')",
                path=path, row=lineno, column=name,
            ) from None
    return out


def _read_arrays(path: str, suffix: str) -> tuple[dict[str, np.ndarray], dict[str, str]]:
    """Variables of a ``.npz``, ``.mat``, ``.parquet`` or ``.h5`` file, squeezed, and
    metadata."""
    meta: dict[str, str] = {}
    if not os.path.exists(path):
        raise FileNotFoundError(2, f"recording {path!r} does not exist", path)
    if suffix in COLUMNAR_SUFFIXES:
        raw, meta = read_columnar(path, suffix)
    elif suffix == ".npz":
        try:
            with np.load(path, allow_pickle=False) as z:
                raw = {k: z[k] for k in z.files}
        except Exception as e:  # noqa: BLE001 - a corrupt file may break the parser anyhow
            raise FileFormatError(
                f"{path}: cannot read as .npz ({e}); save it with numpy.savez and plain "
                "numeric arrays",
                path=path,
            ) from None
        m = raw.pop("_meta", None)
        if m is not None:
            try:
                meta = {str(k): str(v) for k, v in json.loads(str(m)).items()}
            except (ValueError, AttributeError):
                pass
    else:
        import scipy.io

        try:
            raw = scipy.io.loadmat(path, squeeze_me=True)
        except NotImplementedError:
            raise FileFormatError(
                f"{path}: MATLAB v7.3 (HDF5) files are not supported: save it with "
                "save(..., '-v7') in MATLAB, or convert it to CSV",
                path=path,
            ) from None
        except Exception as e:  # noqa: BLE001 - a corrupt file may break the parser anyhow
            raise FileFormatError(
                f"{path}: cannot read as a MATLAB .mat file ({e}): save it with "
                "save(..., '-v7') in MATLAB or scipy.io.savemat, or convert it to CSV",
                path=path,
            ) from None
        raw = {k: v for k, v in raw.items() if not k.startswith("__")}
    arrays: dict[str, np.ndarray] = {}
    for k, v in raw.items():
        a = np.asarray(v)
        if a.dtype.kind in "biuf":
            arrays[k] = np.squeeze(a).astype(float)
    return arrays, meta


#: Position units that ``x_unit`` accepts, with their size in metres (a linear axis's)
#: or in radians (a rotary axis's: ``rad``, ``deg``).
X_UNITS: dict[str, float] = {"m": 1.0, "mm": 1e-3, "um": 1e-6, "cm": 1e-2,
                             "rad": 1.0, "deg": math.pi / 180.0}

#: The units of :data:`X_UNITS` that make a recording a rotary axis's.
ROTARY_X_UNITS = ("rad", "deg")

#: Largest magnitude a recorded value may have: beyond it a product (``K_F*i``, ``x**2``)
#: overflows or swamps every other sample; it is a corrupt cell, not a measurement.
MAX_MAGNITUDE = 1e12


#: Columns every fit and diagnosis uses, checked against :data:`MAX_MAGNITUDE` on reading
#: (references are checked by :func:`lugre.checks.require_plausible`: a file may carry
#: any finite number and still round-trip).
_MEASURED = ("t", "x", "i", "F")


def read_recording(path: str | os.PathLike[str], columns: ColumnSpec = None, *,
                   x_unit: str = "m") -> Recording:
    """Read a recording from CSV, ``.npz``, MATLAB ``.mat``, Parquet or HDF5.

    Parameters
    ----------
    path : str or os.PathLike
        The file. ``.npz``, ``.mat``, ``.parquet`` and ``.h5`` (``.hdf5``) by their
        suffix, anything else as CSV (Parquet needs pyarrow, HDF5 h5py).
    columns : dict or iterable of str or str, optional
        Where to find the recording's columns (``t``, ``x``, ``i``, ``F``, ``v``,
        ``x_ref``, ``v_ref``) when the file names them otherwise: ``{"x": "qm"}``,
        ``["x=qm", "x_ref=qg"]`` or ``"x=qm,x_ref=qg"``. A source may be a product or
        quotient of columns, scalar variables and numbers, e.g. ``"F=gtau*vir"`` or
        ``"x=pos_mm/1000"``. Unmapped columns are taken by their own name when present.
        In ``.mat``/``.npz`` files, ``t`` may be mapped to (or, unmapped, found as) a
        scalar sample time (``dt``, ``Ts``, ``ts``, ``Te``, ...), giving
        ``t = dt*arange(n)``.
    x_unit : {"m", "mm", "um", "cm", "rad", "deg"}
        The unit of the file's positions (``x``, ``x_ref``) and speeds (``v``,
        ``v_ref``, per second); they are converted to metres (``rad`` and ``deg``: to
        radians, a rotary axis's, noted as ``meta["axis_kind"] = "rotary"``) and the
        conversion is noted in ``meta["x_unit"]``.

    Returns
    -------
    Recording
        With ``source`` set to ``path``; ``meta`` from ``# key: value`` lines.

    Raises
    ------
    FileNotFoundError
        No such file.
    FileFormatError
        A cell that is not a number (names the line and the column), a missing
        column (lists the columns found and suggests a mapping), a non-finite value,
        columns of different lengths, or ``t`` not strictly increasing (names the row).
    InputError
        A malformed ``columns`` argument or an unknown ``x_unit``.

    Examples
    --------
    EMPS benchmark, force from the controller output and the drive gain::

        rec = read_recording("DATA_EMPS.mat",
                             columns={"x": "qm", "x_ref": "qg", "F": "gtau*vir"})
    """
    p = os.fspath(path)
    if x_unit not in X_UNITS:
        raise InputError.at("x_unit", f"{x_unit!r} is not a position unit: use one of "
                            f"{', '.join(X_UNITS)}")
    mapping = _parse_columns(columns)
    suffix = Path(p).suffix.lower()
    csv = suffix not in (".npz", ".mat", *COLUMNAR_SUFFIXES)
    if csv:
        meta, header, rows = _read_csv_table(p)
        names: list[str] = header
        cache: dict[str, np.ndarray] = {}

        def get(name: str) -> np.ndarray:
            if name not in cache:
                cache[name] = _csv_column(p, header, rows, name)
            return cache[name]

        def row_of(k: int) -> int:
            return rows[k][0]

        n_rows = len(rows)
    else:
        arrays, meta = _read_arrays(p, suffix)
        names = list(arrays)

        def get(name: str) -> np.ndarray:
            return arrays[name]

        vectors = [a.size for a in arrays.values() if a.ndim == 1]
        n_rows = max(vectors) if vectors else 0

    def source(want: str, expr: str) -> np.ndarray:
        terms = _terms(expr, names)
        if terms is None:
            return get(expr)
        acc: Any = 1.0
        for op, tok in terms:
            if tok in names:
                val: Any = get(tok)
            elif _is_number(tok):
                val = float(tok)
            else:
                raise _missing(p, want, names, tok if len(terms) > 1 else expr)
            acc = acc * val if op == "*" else acc / val
        return np.asarray(acc, dtype=float)

    found: dict[str, np.ndarray] = {}
    origin: dict[str, str] = {}
    for c in COLUMNS:
        if c in mapping:
            found[c] = source(c, mapping[c])
            origin[c] = mapping[c]
        elif c in names:
            found[c] = get(c)
            origin[c] = c

    # time from a scalar sample time (.mat / .npz)
    if not csv and ("t" not in found or found["t"].ndim == 0):
        if "t" in found:
            dt_name, dt = origin["t"], float(found.pop("t"))
        else:
            cand = [k for k in _SAMPLE_TIME_NAMES if k in names and arrays[k].ndim == 0]
            dt_name, dt = (cand[0], float(arrays[cand[0]])) if cand else ("", math.nan)
        if dt_name:
            if not (math.isfinite(dt) and dt > 0.0):
                raise FileFormatError(
                    f"{p}: the sample time {dt_name} = {dt} is not a positive number",
                    path=p, column="t",
                )
            found["t"] = dt * np.arange(n_rows)
            origin["t"] = dt_name
            meta = {**meta, "t": f"built as {dt_name}*arange(n), {dt_name} = {dt!r} s"}

    vector_names = names if csv else [k for k in names if arrays[k].ndim == 1]
    _check_found(p, found, origin, names, vector_names, row_of if csv else None)
    scale = X_UNITS[x_unit]
    if x_unit in ROTARY_X_UNITS:
        meta = {**meta, "axis_kind": "rotary"}
    if scale != 1.0:
        for c in ("x", "x_ref", "v", "v_ref"):
            if c in found:
                found[c] = found[c] * scale
        to = "rad" if x_unit in ROTARY_X_UNITS else "m"
        meta = {**meta, "x_unit": f"positions and speeds read in {x_unit}, converted to {to}"}
    return Recording(**found, meta=meta, source=p)


def _check_found(p: str, found: dict[str, np.ndarray], origin: dict[str, str],
                 names: list[str], vector_names: list[str],
                 row_of: Callable[[int], int] | None) -> None:
    """The columns a recording needs, as vectors of one length, finite, within
    :data:`MAX_MAGNITUDE` (the measured ones) and ``t`` strictly increasing; else
    FileFormatError naming the place (``row_of``: a sample's line in a CSV file, None
    for arrays)."""

    def line(k: int) -> int:
        return row_of(k) if row_of else k

    for want in ("t", "x"):
        if want not in found:
            raise _missing(p, want, names, None, vector_names)
    if "i" not in found and "F" not in found:
        found_list = ", ".join(names)
        raise FileFormatError(
            f"{p}: no column 'i' (motor current [A]) or 'F' (motor force [N]); the file "
            f"has: {found_list}. Map one with columns={{'i': '<column>'}} or "
            "{'F': '<column>'} (a product such as 'F=gain*u' is allowed)",
            path=p, column="i",
        )

    n = found["t"].size if found["t"].ndim == 1 else -1
    for c, a in found.items():
        if a.ndim != 1:
            raise FileFormatError(
                f"{p}: column {c!r} (from {origin[c]!r}) has shape {a.shape}; a "
                "recording column must be a vector",
                path=p, column=c,
            )
        if a.size != n:
            raise FileFormatError(
                f"{p}: column {c!r} (from {origin[c]!r}) has {a.size} samples but t has "
                f"{n}: give columns of the same length",
                path=p, column=c,
            )
    if n == 0:
        raise FileFormatError(f"{p}: the recording is empty", path=p)
    for c, a in found.items():
        bad = np.flatnonzero(~np.isfinite(a))
        if bad.size:
            k = int(bad[0])
            where = f"line {row_of(k)}" if row_of else f"sample {k}"
            raise FileFormatError(
                f"{p}, {where}, column {origin[c]!r}: value {a[k]} is not finite: remove "
                "or interpolate the sample",
                path=p, row=line(k), column=origin[c],
            )
        big = np.flatnonzero(np.abs(a) > MAX_MAGNITUDE) if c in _MEASURED else ()
        if len(big):
            k = int(big[0])
            where = f"line {row_of(k)}" if row_of else f"sample {k}"
            raise FileFormatError(
                f"{p}, {where}, column {origin[c]!r}: value {a[k]:.6g} is beyond any "
                f"measurement (|value| > {MAX_MAGNITUDE:g}): fix or remove the sample",
                path=p, row=line(k), column=origin[c],
            )
    t = found["t"]
    bad = np.flatnonzero(np.diff(t) <= 0.0)
    if bad.size:
        k = int(bad[0]) + 1
        where = f"line {row_of(k)}" if row_of else f"sample {k}"
        raise FileFormatError(
            f"{p}, {where}, column {origin['t']!r}: time is not strictly increasing "
            f"({t[k]!r} after {t[k - 1]!r}): sort the record and drop repeated samples",
            path=p, row=line(k), column=origin["t"],
        )


def write_recording(path: Any, rec: Any) -> None:
    """Write a recording atomically (whole or not at all).

    The two arguments may come in either order (``write_recording(rec, path)``, as
    :func:`lugre.save_model`, or ``write_recording(path, rec)``): one is a
    :class:`Recording` (or a simulation result, see :meth:`Recording.from_simulation`),
    the other the path.

    Parameters
    ----------
    path : str or os.PathLike
        Destination. ``.npz``, ``.mat``, ``.parquet`` and ``.h5`` by suffix (the last
        two keep ``meta`` as the file's metadata), otherwise CSV: the ``meta``
        entries as ``# key: value`` lines, the header, then the numbers in their
        shortest exact (round-trip) form.
    rec : Recording
        The recording. ``.mat`` files do not keep ``meta``.
    """
    if isinstance(path, Recording) or hasattr(path, "friction"):
        path, rec = rec, path
    if hasattr(rec, "friction") and hasattr(rec, "x") and not isinstance(rec, Recording):
        rec = Recording.from_simulation(rec)
    if not isinstance(rec, Recording):
        raise InputError.at("rec", f"expected a lugre.Recording, got {type(rec).__name__}: "
                            "write_recording(recording, path)")
    if not isinstance(path, (str, os.PathLike)):
        raise InputError.at("path", f"expected a file path, got {type(path).__name__}: "
                            "write_recording(recording, path)")
    cols = rec.columns
    suffix = Path(os.fspath(path)).suffix.lower()
    if suffix == ".npz":
        buf = _io.BytesIO()
        extra = {"_meta": np.array(json.dumps(rec.meta))} if rec.meta else {}
        np.savez(buf, **{c: getattr(rec, c) for c in cols}, **extra)
        data = buf.getvalue()
    elif suffix in COLUMNAR_SUFFIXES:
        data = write_columnar(suffix, os.fspath(path), {c: getattr(rec, c) for c in cols},
                              rec.meta)
    elif suffix == ".mat":
        import scipy.io

        buf = _io.BytesIO()
        scipy.io.savemat(buf, {c: getattr(rec, c) for c in cols}, oned_as="column")
        data = buf.getvalue()
    else:
        lines = []
        for k, val in rec.meta.items():
            key = str(k).replace("\n", " ").replace(":", "_").strip()
            lines.append(f"# {key}: {str(val).splitlines()[0] if str(val) else ''}")
        lines.append(",".join(cols))
        table = np.column_stack([getattr(rec, c) for c in cols]).tolist()
        lines.extend(",".join(map(repr, row)) for row in table)
        data = ("\n".join(lines) + "\n").encode("utf-8")
    _atomic_write(path, data)


def is_points_file(path: str | os.PathLike[str]) -> bool:
    """True for a CSV of steady-state points: columns ``v`` and ``F`` and no ``t``."""
    p = os.fspath(path)
    if not p.lower().endswith(".csv"):
        return False
    _, header, _ = _read_csv_table(p)
    return "v" in header and "F" in header and "t" not in header


def read_points(path: str | os.PathLike[str]) -> tuple[np.ndarray, np.ndarray]:
    """Steady-state points ``(v [m/s], F [N])`` from a CSV with columns ``v`` and ``F``.

    Raises
    ------
    FileFormatError
        A column is missing or a cell is not a number (the message names the line).
    """
    p = os.fspath(path)
    _, header, rows = _read_csv_table(p)
    for name in ("v", "F"):
        if name not in header:
            raise FileFormatError(
                f"{p}: no column {name!r} (found {', '.join(header)}): steady-state points "
                "need columns 'v' [m/s] and 'F' [N]",
                path=p, column=name,
            )
    out = []
    for name in ("v", "F"):
        a = _csv_column(p, header, rows, name)
        bad = np.flatnonzero(~np.isfinite(a) | (np.abs(a) > MAX_MAGNITUDE))
        if bad.size:
            k = int(bad[0])
            raise FileFormatError(
                f"{p}, line {rows[k][0]}, column {name!r}: value {a[k]:.6g} is not a "
                "finite measurement: fix or remove the row",
                path=p, row=rows[k][0], column=name,
            )
        out.append(a)
    return out[0], out[1]
