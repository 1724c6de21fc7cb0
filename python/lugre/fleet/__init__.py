"""A fleet of axes: every recording diagnosed against its axis's model on a Dask cluster,
the results kept in a DuckDB history, trends and alarms from it (CONTRACT, "Fleet").

>>> import lugre.fleet
>>> s = lugre.fleet.run("plant/", "fleet.duckdb", workers=2)          # doctest: +SKIP
>>> doc = lugre.fleet.report("fleet.duckdb", json="ALARMS.json")      # doctest: +SKIP

Dask, DuckDB, pyarrow and h5py are optional: ``pip install 'lugre[fleet]'``.
"""

from __future__ import annotations

from .alarms import Alarm
from .discover import RECORDING_SUFFIXES, discover
from .report import report
from .run import RunSummary, run

__all__ = ["RECORDING_SUFFIXES", "Alarm", "RunSummary", "discover", "report", "run"]
