"""The fleet's folder: one folder per axis with its ``model.json`` and its recordings, and
each recording's time (its ``time`` metadata, else an ISO date in its file name)."""

from __future__ import annotations

import datetime as _dt
import os
import re
from dataclasses import dataclass, field
from pathlib import Path

from ..exceptions import FileFormatError, InputError

__all__ = ["RECORDING_SUFFIXES", "Axis", "discover", "file_stamp", "parse_time",
           "time_from_name"]

#: Suffixes of the recordings of an axis's folder (CONTRACT, "Fleet").
RECORDING_SUFFIXES = (".csv", ".mat", ".npz", ".parquet", ".h5")

#: An ISO date in a file name, with an optional time: ``2024-03-01``,
#: ``2024-03-01T0200``, ``2024-03-01T02-00-30``, ``2024-03-01_020030``.
_NAME_TIME = re.compile(r"(\d{4})-(\d{2})-(\d{2})(?:[T_ ](\d{2})[-:]?(\d{2})(?:[-:]?(\d{2}))?)?")


@dataclass
class Axis:
    """One axis of the fleet: its name (the folder's), its model file and recordings."""

    name: str
    folder: Path
    model: Path
    recordings: list[Path] = field(default_factory=list)


def discover(root: str | os.PathLike[str]) -> list[Axis]:
    """The axes under ``root``, sorted by name, each with its recordings sorted by name.

    Hidden folders (``.name``) are passed over. A folder with recordings but no
    ``model.json`` is refused (the fleet cannot tell what to check them against).

    Raises
    ------
    FileNotFoundError
        ``root`` does not exist.
    InputError
        ``root`` is not a folder, holds no axis folder, or an axis has no model.json.
    """
    top = Path(root)
    if not top.exists():
        raise FileNotFoundError(2, f"fleet folder {os.fspath(root)} does not exist: give the "
                                "folder that holds one folder per axis", os.fspath(root))
    if not top.is_dir():
        raise InputError(f"{os.fspath(root)} is not a folder: give the folder that holds "
                         "one folder per axis (DIR/AXIS/model.json)", name="DIR")
    axes = []
    for folder in sorted(p for p in top.iterdir() if p.is_dir() and not p.name.startswith(".")):
        recs = sorted(p for p in folder.iterdir()
                      if p.is_file() and p.suffix.lower() in RECORDING_SUFFIXES)
        model = folder / "model.json"
        if not model.is_file():
            if not recs:
                continue
            raise InputError(f"{folder}: no model.json beside its {len(recs)} recordings: put "
                             "the axis's model there (lugre fit RECORDING --json model.json "
                             "writes one)", name="DIR")
        axes.append(Axis(folder.name, folder, model, recs))
    if not axes:
        raise InputError(f"{os.fspath(root)} holds no axis folder: give one folder per axis, "
                         "each with its model.json and recordings", name="DIR")
    return axes


def file_stamp(path: Path) -> str:
    """Size and modification time of a file: a recording replaced since is diagnosed again."""
    st = path.stat()
    return f"{st.st_size}:{st.st_mtime_ns}"


def parse_time(text: str, source: str) -> _dt.datetime:
    """An ISO-8601 time as a naive UTC time (a time without a zone is taken as written).

    Raises
    ------
    FileFormatError
        ``text`` is not an ISO-8601 date or time.
    """
    s = text.strip()
    if s.endswith(("Z", "z")):
        s = s[:-1] + "+00:00"
    try:
        t = _dt.datetime.fromisoformat(s)
    except ValueError:
        raise FileFormatError(f"{source}: time {text!r} is not an ISO-8601 time: write it "
                              "as 2024-03-01T02:00:00Z", path=source) from None
    if t.tzinfo is not None:
        t = t.astimezone(_dt.timezone.utc).replace(tzinfo=None)
    return t


def time_from_name(name: str) -> _dt.datetime | None:
    """The date (and time) in a file name, or None."""
    m = _NAME_TIME.search(name)
    if not m:
        return None
    parts = [int(g) if g else 0 for g in m.groups()]
    try:
        return _dt.datetime(*parts)
    except ValueError:
        return None
