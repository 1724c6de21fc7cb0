"""Recordings: read and write the CONTRACT recording format (CSV, ``.npz``, MATLAB ``.mat``).

This module gathers the names of :mod:`lugre.recording` (the :class:`Recording`),
:mod:`lugre.columns` (column mappings and expressions), :mod:`lugre.readers` (files),
:mod:`lugre.tabular` (tables with named columns) and :mod:`lugre.checks` (refusing
recordings a fit or a diagnosis cannot use) under one roof.
"""

from __future__ import annotations

from ._atomic import _atomic_write, atomic_write
from .checks import require_plausible, resample_uniform
from .columns import ColumnSpec, _parse_columns, parse_columns
from .readers import is_points_file, read_points, read_recording, write_recording
from .recording import COLUMNS, Recording
from .tabular import as_recording

__all__ = [
    "COLUMNS",
    "ColumnSpec",
    "Recording",
    "as_recording",
    "atomic_write",
    "is_points_file",
    "parse_columns",
    "read_points",
    "read_recording",
    "require_plausible",
    "resample_uniform",
    "write_recording",
]

_ = (_atomic_write, _parse_columns)
