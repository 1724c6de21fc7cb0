"""Recordings: read and write the CONTRACT recording format (CSV, ``.npz``, MATLAB ``.mat``).

A recording holds ``t`` [s] (strictly increasing), ``x`` [m], and the motor current ``i``
[A] or the motor force ``F`` [N]; optionally ``v`` [m/s], ``x_ref`` [m] and ``v_ref``
[m/s]. CSV files may start with ``#`` lines (``# key: value`` lines become
:attr:`Recording.meta`), then one header line, then comma-separated numbers.

Files with other names are read through a column mapping, ``{"x": "qm"}`` or the strings
``"x=qm"``. A mapped source may also be a product or quotient of columns, scalars stored
in the file and numbers, which covers the usual unit conversions; for the EMPS benchmark
(``DATA_EMPS.mat``: ``qm``, ``qg``, ``vir`` [V], ``gtau`` [N/V], ``t``)::

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
import re
import tempfile
import zipfile
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Union

import numpy as np

from .exceptions import FileFormatError, InputError, _fmt_f64

__all__ = [
    "COLUMNS",
    "Recording",
    "is_points_file",
    "read_points",
    "read_recording",
    "write_recording",
]

#: Column names of a recording, in the order they are written.
COLUMNS: tuple[str, ...] = ("t", "x", "i", "F", "v", "x_ref", "v_ref")

_DESCRIPTION = {
    "t": "time [s]",
    "x": "measured position [m]",
    "i": "motor current [A]",
    "F": "motor force [N]",
    "v": "measured velocity [m/s]",
    "x_ref": "position reference [m]",
    "v_ref": "velocity reference [m/s]",
}

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


# --------------------------------------------------------------------------------------
# Atomic writes (shared with lugre.model.save_model)
# --------------------------------------------------------------------------------------


def _atomic_write(path: str | os.PathLike[str], data: bytes) -> None:
    """Write ``data`` to ``path`` whole or not at all.

    The bytes go to a temporary file in the destination's directory, are flushed to
    disk, and the temporary file then replaces ``path`` (:func:`os.replace` is atomic
    within one file system). On any error the temporary file is removed and ``path`` is
    left as it was.
    """
    dest = Path(path)
    directory = dest.parent if str(dest.parent) else Path(".")
    fd, tmp = tempfile.mkstemp(dir=directory, prefix=f".{dest.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
        try:
            mode = os.stat(dest).st_mode & 0o777
        except FileNotFoundError:
            umask = os.umask(0)
            os.umask(umask)
            mode = 0o666 & ~umask
        os.chmod(tmp, mode)
        os.replace(tmp, dest)
    except BaseException:
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass
        raise


# --------------------------------------------------------------------------------------
# Recording
# --------------------------------------------------------------------------------------


def _column_array(name: str, a: Any) -> np.ndarray:
    arr = np.asarray(a, dtype=float)
    if arr.ndim != 1:
        arr = np.squeeze(arr)
        if arr.ndim != 1:
            raise InputError.at(
                name, f"must be one-dimensional, got shape {np.shape(a)}: give a vector"
            )
    return np.ascontiguousarray(arr)


@dataclass
class Recording:
    """A sampled record of an axis.

    Parameters
    ----------
    t : array_like
        Time [s], strictly increasing.
    x : array_like
        Measured position [m].
    i : array_like, optional
        Motor current [A] (command or measurement). ``i`` or ``F`` must be given.
    F : array_like, optional
        Motor force [N].
    v : array_like, optional
        Measured velocity [m/s].
    x_ref, v_ref : array_like, optional
        Position [m] or velocity [m/s] reference.
    meta : dict, optional
        Metadata, from the ``# key: value`` lines of a CSV file.
    source : str, optional
        The file it was read from.

    Raises
    ------
    InputError
        Arrays of different lengths, empty, not finite, or ``t`` not strictly
        increasing; neither ``i`` nor ``F`` given.

    Examples
    --------
    >>> r = Recording(t=[0.0, 0.001, 0.002], x=[0.0, 1e-5, 2e-5], i=[1.0, 1.0, 1.1])
    >>> r.force(25.0)
    array([25. , 25. , 27.5])
    """

    t: np.ndarray
    x: np.ndarray
    i: np.ndarray | None = None
    F: np.ndarray | None = None
    v: np.ndarray | None = None
    x_ref: np.ndarray | None = None
    v_ref: np.ndarray | None = None
    meta: dict[str, str] = field(default_factory=dict)
    source: str | None = None

    def __post_init__(self) -> None:
        for name in COLUMNS:
            a = getattr(self, name)
            if a is not None:
                setattr(self, name, _column_array(name, a))
        if self.i is None and self.F is None:
            raise InputError.at(
                "i", "a recording needs the motor current i or the motor force F: give one"
            )
        n = self.t.size
        if n == 0:
            raise InputError.at("t", "is empty: give at least one sample")
        for name in self.columns:
            a = getattr(self, name)
            if a.size != n:
                raise InputError.at(
                    name,
                    f"has {a.size} samples but t has {n}: give arrays of the same length",
                )
            bad = np.flatnonzero(~np.isfinite(a))
            if bad.size:
                k = int(bad[0])
                raise InputError.at(
                    name,
                    f"element {k} is {_fmt_f64(a[k])} : remove or interpolate non-finite "
                    "samples",
                )
        bad = np.flatnonzero(np.diff(self.t) <= 0.0)
        if bad.size:
            k = int(bad[0]) + 1
            raise InputError.at(
                "t",
                f"time is not strictly increasing at element {k} ({_fmt_f64(self.t[k])} "
                f"after {_fmt_f64(self.t[k - 1])}): sort the record and drop repeated "
                "samples",
            )
        self.meta = dict(self.meta)

    @property
    def columns(self) -> tuple[str, ...]:
        """Names of the columns present, in :data:`COLUMNS` order."""
        return tuple(c for c in COLUMNS if getattr(self, c) is not None)

    def __len__(self) -> int:
        return int(self.t.size)

    @property
    def dt(self) -> float:
        """Median sample interval [s] (``nan`` for a single sample)."""
        return float(np.median(np.diff(self.t))) if self.t.size > 1 else math.nan

    def force(self, force_constant: float | Any | None = None) -> np.ndarray:
        """The motor force [N]: ``F`` when recorded, else ``force_constant * i``.

        Parameters
        ----------
        force_constant : float or Model, optional
            K_F [N/A] (or a model, whose ``force_constant`` is used). Needed only when
            the recording holds the current ``i`` and not ``F``.

        Returns
        -------
        numpy.ndarray
            A new array.
        """
        if self.F is not None:
            return self.F.copy()
        if force_constant is None:
            raise InputError.at(
                "force_constant",
                "the recording holds the current i, not the force F: give the force "
                "constant K_F [N/A] (or the model)",
            )
        kf = getattr(force_constant, "force_constant", force_constant)
        kf = float(kf)
        if not (math.isfinite(kf) and kf > 0.0):
            raise InputError.at("force_constant", f"is {kf}: give a positive K_F [N/A]")
        assert self.i is not None
        return kf * self.i

    def slice(self, which: Any) -> Recording:
        """The samples selected by a boolean mask or a time range.

        Parameters
        ----------
        which : array_like of bool, or (t_start, t_end)
            A mask of the recording's length, or a time range; ``t_start <= t <= t_end``
            is kept and either end may be ``None``.

        Returns
        -------
        Recording
            A new recording with copies of the selected samples (same ``meta`` and
            ``source``).
        """
        if isinstance(which, tuple) and len(which) == 2:
            lo, hi = which
            mask = np.ones(self.t.size, dtype=bool)
            if lo is not None:
                mask &= self.t >= float(lo)
            if hi is not None:
                mask &= self.t <= float(hi)
        else:
            mask = np.asarray(which)
            if mask.dtype != bool or mask.shape != self.t.shape:
                raise InputError.at(
                    "which",
                    f"must be a boolean mask of {self.t.size} samples or a "
                    "(t_start, t_end) pair",
                )
        kw: dict[str, Any] = {
            c: getattr(self, c)[mask].copy() for c in self.columns
        }
        return Recording(**kw, meta=dict(self.meta), source=self.source)

    def to_dict(self) -> dict[str, np.ndarray]:
        """The columns present, as a dict of arrays (not copies)."""
        return {c: getattr(self, c) for c in self.columns}

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Recording):
            return NotImplemented
        if self.columns != other.columns or self.meta != other.meta:
            return False
        return all(np.array_equal(getattr(self, c), getattr(other, c)) for c in self.columns)

    __hash__ = None  # type: ignore[assignment]


# --------------------------------------------------------------------------------------
# Column mapping
# --------------------------------------------------------------------------------------


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
                raise ValueError(
                    f"column mapping {spec!r} is not of the form 'name=source', "
                    "e.g. 'x=qm' or 'F=gtau*vir'"
                )
            k, _, val = spec.partition("=")
            items.append((k, val))
    out: dict[str, str] = {}
    for k, val in items:
        k, val = str(k).strip(), str(val).strip()
        if k not in COLUMNS:
            raise ValueError(
                f"column mapping names {k!r}, which is not a recording column: "
                f"use {', '.join(COLUMNS)}"
            )
        if not val:
            raise ValueError(f"column mapping for {k!r} is empty")
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


# --------------------------------------------------------------------------------------
# Readers
# --------------------------------------------------------------------------------------


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
    """Variables of a ``.npz`` or ``.mat`` file, squeezed, and metadata."""
    meta: dict[str, str] = {}
    if not os.path.exists(path):
        raise FileNotFoundError(2, f"recording {path!r} does not exist", path)
    if suffix == ".npz":
        try:
            with np.load(path, allow_pickle=False) as z:
                raw = {k: z[k] for k in z.files}
        except (ValueError, OSError, zipfile.BadZipFile) as e:
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
        except (ValueError, OSError, TypeError) as e:
            raise FileFormatError(
                f"{path}: cannot read as a MATLAB .mat file ({e})", path=path
            ) from None
        raw = {k: v for k, v in raw.items() if not k.startswith("__")}
    arrays: dict[str, np.ndarray] = {}
    for k, v in raw.items():
        a = np.asarray(v)
        if a.dtype.kind in "biuf":
            arrays[k] = np.squeeze(a).astype(float)
    return arrays, meta


def read_recording(path: str | os.PathLike[str], columns: ColumnSpec = None) -> Recording:
    """Read a recording from CSV, ``.npz`` or MATLAB ``.mat``.

    Parameters
    ----------
    path : str or os.PathLike
        The file. ``.npz`` and ``.mat`` by their suffix, anything else as CSV.
    columns : dict or iterable of str or str, optional
        Where to find the recording's columns (``t``, ``x``, ``i``, ``F``, ``v``,
        ``x_ref``, ``v_ref``) when the file names them otherwise: ``{"x": "qm"}``,
        ``["x=qm", "x_ref=qg"]`` or ``"x=qm,x_ref=qg"``. A source may be a product or
        quotient of columns, scalar variables and numbers, e.g. ``"F=gtau*vir"`` or
        ``"x=pos_mm/1000"``. Unmapped columns are taken by their own name when present.
        In ``.mat``/``.npz`` files, ``t`` may be mapped to (or, unmapped, found as) a
        scalar sample time (``dt``, ``Ts``, ``ts``, ``Te``, ...), giving
        ``t = dt*arange(n)``.

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
    ValueError
        A malformed ``columns`` argument.

    Examples
    --------
    EMPS benchmark, force from the controller output and the drive gain::

        rec = read_recording("DATA_EMPS.mat",
                             columns={"x": "qm", "x_ref": "qg", "F": "gtau*vir"})
    """
    p = os.fspath(path)
    mapping = _parse_columns(columns)
    suffix = Path(p).suffix.lower()
    csv = suffix not in (".npz", ".mat")
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

        def row_of(k: int) -> int:
            return k

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

    if csv:
        vector_names = names
    else:
        vector_names = [k for k in names if arrays[k].ndim == 1]
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
            where = f"line {row_of(k)}" if csv else f"sample {k}"
            raise FileFormatError(
                f"{p}, {where}, column {origin[c]!r}: value {a[k]} is not finite: remove "
                "or interpolate the sample",
                path=p, row=row_of(k), column=origin[c],
            )
    t = found["t"]
    bad = np.flatnonzero(np.diff(t) <= 0.0)
    if bad.size:
        k = int(bad[0]) + 1
        where = f"line {row_of(k)}" if csv else f"sample {k}"
        raise FileFormatError(
            f"{p}, {where}, column {origin['t']!r}: time is not strictly increasing "
            f"({t[k]!r} after {t[k - 1]!r}): sort the record and drop repeated samples",
            path=p, row=row_of(k), column=origin["t"],
        )
    return Recording(**found, meta=meta, source=p)


# --------------------------------------------------------------------------------------
# Writer
# --------------------------------------------------------------------------------------


def write_recording(path: str | os.PathLike[str], rec: Recording) -> None:
    """Write a recording atomically (whole or not at all).

    Parameters
    ----------
    path : str or os.PathLike
        Destination. ``.npz`` and ``.mat`` by suffix, otherwise CSV: the ``meta``
        entries as ``# key: value`` lines, the header, then the numbers in their
        shortest exact (round-trip) form.
    rec : Recording
        The recording. ``.mat`` files do not keep ``meta``.
    """
    if not isinstance(rec, Recording):
        raise TypeError(f"expected a lugre.io.Recording, got {type(rec).__name__}")
    cols = rec.columns
    suffix = Path(os.fspath(path)).suffix.lower()
    if suffix == ".npz":
        buf = _io.BytesIO()
        extra = {"_meta": np.array(json.dumps(rec.meta))} if rec.meta else {}
        np.savez(buf, **{c: getattr(rec, c) for c in cols}, **extra)
        data = buf.getvalue()
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
    return _csv_column(p, header, rows, "v"), _csv_column(p, header, rows, "F")
