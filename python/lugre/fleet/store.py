"""The fleet's history: one DuckDB file, every recording's result written in one
transaction (all its rows or none), and a Parquet export of each table.

Tables (``axis``, ``recording``: the axis's folder and the recording's file name):

- ``axes``: the axis's kind (``linear``/``rotary``), its units, its model (JSON text);
- ``recordings``: ``time``, ``status`` (``ok``/``error``), ``error``, ``nrmse_force`` (the
  model as given), ``nrmse_after`` (with the findings), ``n_findings``, the verdict,
  what stayed unexplained, the file's size and time stamp (a replaced file is diagnosed
  again);
- ``findings``: one row per finding: ``effect``, ``parameters`` and ``intervals`` (JSON
  text), ``explained``, the held-out gain, p and blocks, ``evidence``;
- ``levels``: per direction the Coulomb level refitted on the record (``refit_fc``) and
  at the record's end (``level``: times the change of a ``drift`` found on it), the
  model's (``model_fc``), the friction the model misses on the record (``shift``, with
  its standard error ``se``);
- ``limits``: what the record could not have revealed (smallest size per effect).
"""

from __future__ import annotations

import datetime as _dt
import json
import os
from pathlib import Path
from typing import Any, final

from ..exceptions import InputError

__all__ = ["TABLES", "Store", "open_store"]

_SCHEMA = """
CREATE TABLE IF NOT EXISTS axes (
    axis VARCHAR PRIMARY KEY, kind VARCHAR, position_unit VARCHAR, force_unit VARCHAR,
    model VARCHAR, updated TIMESTAMP);
CREATE TABLE IF NOT EXISTS recordings (
    axis VARCHAR, recording VARCHAR, time TIMESTAMP, status VARCHAR, error VARCHAR,
    nrmse_force DOUBLE, nrmse_after DOUBLE, rms_force DOUBLE, n_findings INTEGER,
    samples INTEGER, duration DOUBLE, verdict VARCHAR, unexplained VARCHAR,
    seconds DOUBLE, path VARCHAR, stamp VARCHAR, stored TIMESTAMP,
    PRIMARY KEY (axis, recording));
CREATE TABLE IF NOT EXISTS findings (
    axis VARCHAR, recording VARCHAR, time TIMESTAMP, rank INTEGER, effect VARCHAR,
    parameters VARCHAR, intervals VARCHAR, "where" VARCHAR, explained DOUBLE,
    held_out_gain DOUBLE, held_out_p DOUBLE, blocks_better INTEGER, evidence VARCHAR,
    PRIMARY KEY (axis, recording, rank));
CREATE TABLE IF NOT EXISTS levels (
    axis VARCHAR, recording VARCHAR, time TIMESTAMP, direction VARCHAR, level DOUBLE,
    refit_fc DOUBLE, model_fc DOUBLE, shift DOUBLE, se DOUBLE,
    PRIMARY KEY (axis, recording, direction));
CREATE TABLE IF NOT EXISTS limits (
    axis VARCHAR, recording VARCHAR, time TIMESTAMP, effect VARCHAR, smallest DOUBLE,
    unit VARCHAR, text VARCHAR);
"""

#: The tables, in the order they are exported.
TABLES = ("axes", "recordings", "findings", "levels", "limits")


def _duckdb() -> Any:
    try:
        import duckdb
    except ImportError:
        raise InputError("the fleet's history needs the Python package duckdb, which is not "
                         "installed: pip install 'lugre[fleet]'", name="--db") from None
    return duckdb


def open_store(path: str | os.PathLike[str], read_only: bool = False) -> Store:
    """Open (or create, unless ``read_only``) the history at ``path``.

    Raises
    ------
    FileNotFoundError
        ``read_only`` and no such file.
    InputError
        The file is not a DuckDB database, or another process holds it.
    """
    duckdb = _duckdb()
    p = os.fspath(path)
    if read_only and not os.path.isfile(p):
        raise FileNotFoundError(2, f"fleet history {p} does not exist: run lugre fleet run "
                                f"DIR --db {p} first", p)
    if not read_only:
        _writable(p)
    try:
        con = duckdb.connect(p, read_only=read_only)
    except duckdb.Error as e:
        text = " ".join(str(e).split())
        if "lock" in text.lower():
            why = "another process (a running lugre fleet run?) holds it: wait for it to end"
        else:
            why = ("it is not a fleet history (DuckDB) file: give a new file name or the one "
                   "lugre fleet run wrote")
        raise InputError(f"cannot open {p}: {why} ({text})", name="--db") from None
    store = Store(con, p)
    if not read_only:
        con.execute(_SCHEMA)
    else:
        missing = [t for t in TABLES if t not in store.table_names()]
        if missing:
            con.close()
            raise InputError(f"{p} is not a fleet history (no table {', '.join(missing)}): "
                             "give the file lugre fleet run wrote", name="--db")
    return store


def _writable(p: str) -> None:
    """Refuse a history that cannot be written, before any work."""
    parent = os.path.dirname(os.path.abspath(p))
    if not os.path.isdir(parent):
        raise FileNotFoundError(2, f"cannot write {p}: the directory {parent} does not exist: "
                                "create it first or choose another path", p)
    if os.path.isdir(p):
        raise IsADirectoryError(21, f"cannot write {p}: it is a directory: give a file name", p)
    if not os.access(p if os.path.exists(p) else parent, os.W_OK):
        raise PermissionError(13, f"cannot write {p}: no permission to write "
                              f"{'it' if os.path.exists(p) else 'in ' + parent}: choose another "
                              "path", p)


def _time(text: str | None) -> _dt.datetime | None:
    return _dt.datetime.fromisoformat(text) if text else None


@final
class Store:
    """An open fleet history (see :func:`open_store`); a context manager."""

    def __init__(self, con: Any, path: str) -> None:
        self.con = con
        self.path = path

    def __enter__(self) -> Store:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        self.con.close()

    def table_names(self) -> list[str]:
        return [r[0] for r in self.con.execute("SELECT table_name FROM "
                                               "information_schema.tables").fetchall()]

    def stamps(self) -> dict[tuple[str, str], str]:
        """The stored recordings with the file stamp each was diagnosed from."""
        rows = self.con.execute("SELECT axis, recording, stamp FROM recordings").fetchall()
        return {(a, r): s for a, r, s in rows}

    def put_axis(self, axis: str, kind: str, units: dict[str, str],
                 model: dict[str, Any]) -> None:
        self.con.execute(
            "INSERT OR REPLACE INTO axes VALUES (?, ?, ?, ?, ?, ?)",
            [axis, kind, units.get("position"), units.get("force"), json.dumps(model),
             _dt.datetime.now(_dt.timezone.utc).replace(tzinfo=None)])

    def put(self, result: dict[str, Any]) -> None:
        """Store one recording's result: its rows in every table, in one transaction
        (a recording stored before under the same name is replaced)."""
        key = [result["axis"], result["recording"]]
        when = _time(result.get("time"))
        con = self.con
        con.execute("BEGIN TRANSACTION")
        try:
            # (a recording's rows are written in one transaction, so one without a row in
            # recordings has none anywhere: only a stored one needs its rows deleted)
            if con.execute("SELECT 1 FROM recordings WHERE axis = ? AND recording = ?",
                           key).fetchone():
                for table in ("recordings", "findings", "levels", "limits"):
                    con.execute(f"DELETE FROM {table} WHERE axis = ? AND recording = ?", key)
            con.execute(
                "INSERT INTO recordings VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, "
                "?, ?)",
                [*key, when, result["status"], result.get("error"),
                 result.get("nrmse_force"), result.get("nrmse_after"),
                 result.get("rms_force"), len(result.get("findings", [])),
                 result.get("samples"), result.get("duration"), result.get("verdict"),
                 result.get("unexplained"), result.get("seconds"), result.get("path"),
                 result.get("stamp"), _dt.datetime.now(_dt.timezone.utc).replace(tzinfo=None)])
            self._rows(result, key, when)
            con.execute("COMMIT")
        except BaseException:
            con.execute("ROLLBACK")
            raise

    def _rows(self, result: dict[str, Any], key: list[str], when: Any) -> None:
        _insert(self.con, "findings", [
            [*key, when, f["rank"], f["effect"], json.dumps(f["parameters"]),
             json.dumps(f.get("intervals") or {}), json.dumps(f.get("where")),
             f.get("explained"), f.get("held_out_gain"), f.get("held_out_p"),
             f.get("blocks_better"), f.get("evidence")] for f in result.get("findings", [])])
        _insert(self.con, "levels", [
            [*key, when, lv["direction"], lv.get("level"), lv.get("refit_fc"),
             lv["model_fc"], lv.get("shift"), lv.get("se")] for lv in result.get("levels", [])])
        _insert(self.con, "limits", [
            [*key, when, lim.get("effect"), lim.get("smallest"), lim.get("unit"),
             lim.get("text")] for lim in result.get("limits", [])])

    def rows(self, sql: str, params: list[Any] | None = None) -> list[dict[str, Any]]:
        """The rows of a query as dicts."""
        cur = self.con.execute(sql, params or [])
        names = [d[0] for d in cur.description]
        return [dict(zip(names, r)) for r in cur.fetchall()]

    def export_parquet(self, outdir: str | os.PathLike[str]) -> list[Path]:
        """Each table as ``OUTDIR/TABLE.parquet``, each file written whole (a temporary
        file beside it, then renamed)."""
        out = Path(outdir)
        written = []
        for table in TABLES:
            dest = out / f"{table}.parquet"
            tmp = out / f".{table}.parquet.{os.getpid()}.tmp"
            try:
                self.con.execute(f"COPY {table} TO '{_quoted(tmp)}' (FORMAT PARQUET)")
                os.replace(tmp, dest)
            finally:
                if tmp.exists():
                    tmp.unlink()
            written.append(dest)
        return written


def _insert(con: Any, table: str, rows: list[list[Any]]) -> None:
    """All ``rows`` into ``table`` in one statement (a statement a row cost the client
    30 ms a recording, a sixth of a worker's diagnosis on a 2-core machine)."""
    if not rows:
        return
    one = "(" + ", ".join("?" * len(rows[0])) + ")"
    con.execute(f"INSERT INTO {table} VALUES " + ", ".join([one] * len(rows)),
                [v for r in rows for v in r])


def _quoted(p: Path) -> str:
    return os.fspath(p).replace("'", "''")
