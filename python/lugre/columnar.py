"""Recordings in columnar files: Parquet (pyarrow) and HDF5 (h5py), with the columns of a
CSV recording (``t``, ``x``, ``i`` or ``F``, optional ``v``, ``x_ref``, ``v_ref``).

A Parquet file holds one column per quantity; its schema's key-value metadata are the
recording's ``meta`` (``time`` among them). An HDF5 file holds one dataset per quantity at
its root (a scalar dataset such as ``dt`` is a sample time); the root's attributes are
``meta``. pyarrow and h5py are optional (``pip install lugre[fleet]``): they are imported
here, when such a file is read or written, and a missing one is said with the fix.
"""

from __future__ import annotations

import io
from typing import Any

import numpy as np

from .exceptions import FileFormatError

__all__ = ["COLUMNAR_SUFFIXES", "read_columnar", "write_columnar"]

#: File suffixes read and written here, each with the optional package it needs.
COLUMNAR_SUFFIXES = {".parquet": "pyarrow", ".h5": "h5py", ".hdf5": "h5py"}

#: Metadata keys that Parquet writers add for themselves (not the recording's).
_WRITER_KEYS = ("pandas", "ARROW:schema")


def _module(path: str, suffix: str) -> Any:
    name = COLUMNAR_SUFFIXES[suffix]
    try:
        if name == "pyarrow":
            import pyarrow.parquet as pq

            return pq
        import h5py

        return h5py
    except ImportError:
        raise FileFormatError(
            f"{path}: reading or writing {suffix} recordings needs the Python package "
            f"{name}, which is not installed: pip install {name} (or pip install "
            "'lugre[fleet]'), or convert the file to CSV", path=path) from None


def read_columnar(path: str, suffix: str) -> tuple[dict[str, np.ndarray], dict[str, str]]:
    """The numeric columns (or datasets) of a Parquet or HDF5 file, and its metadata."""
    mod = _module(path, suffix)
    try:
        if suffix == ".parquet":
            return _read_parquet(mod, path)
        return _read_hdf5(mod, path)
    except FileFormatError:
        raise
    except Exception as e:  # noqa: BLE001 - a corrupt file may break the parser anyhow
        kind = "Parquet" if suffix == ".parquet" else "HDF5"
        raise FileFormatError(
            f"{path}: cannot read as a {kind} file ({e}): write it again with one numeric "
            "column per quantity (t, x, i or F), or convert it to CSV", path=path) from None


def _read_parquet(pq: Any, path: str) -> tuple[dict[str, np.ndarray], dict[str, str]]:
    table = pq.read_table(path)
    arrays: dict[str, np.ndarray] = {}
    for name in table.column_names:
        a = table.column(name).to_numpy(zero_copy_only=False)
        if np.asarray(a).dtype.kind in "biuf":
            arrays[str(name)] = np.asarray(a, dtype=float)
    raw = table.schema.metadata or {}
    meta = {k.decode("utf-8", "replace"): v.decode("utf-8", "replace")
            for k, v in raw.items() if k.decode("utf-8", "replace") not in _WRITER_KEYS}
    return arrays, meta


def _read_hdf5(h5py: Any, path: str) -> tuple[dict[str, np.ndarray], dict[str, str]]:
    arrays: dict[str, np.ndarray] = {}
    with h5py.File(path, "r") as f:
        for name, item in f.items():
            if isinstance(item, h5py.Dataset) and item.dtype.kind in "biuf":
                arrays[str(name)] = np.squeeze(np.asarray(item[()], dtype=float))
        meta = {str(k): _text(v) for k, v in f.attrs.items()}
    return arrays, meta


def _text(v: Any) -> str:
    if isinstance(v, bytes):
        return v.decode("utf-8", "replace")
    if isinstance(v, np.ndarray) and v.ndim == 0:
        return _text(v.item())
    return str(v)


def write_columnar(suffix: str, path: str, columns: dict[str, np.ndarray],
                   meta: dict[str, str]) -> bytes:
    """The bytes of a Parquet or HDF5 recording file (written by the caller, whole)."""
    mod = _module(path, suffix)
    buf = io.BytesIO()
    if suffix == ".parquet":
        import pyarrow as pa

        table = pa.table({k: np.asarray(v, dtype=float) for k, v in columns.items()})
        table = table.replace_schema_metadata({str(k): str(v) for k, v in meta.items()})
        mod.write_table(table, buf)
    else:
        with mod.File(buf, "w") as f:
            for k, v in columns.items():
                f.create_dataset(k, data=np.asarray(v, dtype=float))
            for k, v in meta.items():
                f.attrs[str(k)] = str(v)
    return buf.getvalue()

