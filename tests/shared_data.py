"""The data the tests read (``tests/data``: the public diagnosis cases, the static
points and the real EMPS records, see its README), unpacked once per content into a
folder under the system's temporary directory with their layout kept."""

from __future__ import annotations

import gzip
import hashlib
import os
import shutil
import tempfile
from pathlib import Path

import pytest

DATA = Path(__file__).resolve().parent / "data"


def _unpack() -> Path:
    files = sorted(p for p in DATA.rglob("*") if p.is_file())
    h = hashlib.sha256()
    for p in files:
        h.update(str(p.relative_to(DATA)).encode())
        h.update(p.read_bytes())
    root = Path(tempfile.gettempdir()) / f"lugre-test-data-{h.hexdigest()[:16]}"
    if root.is_dir():
        return root
    tmp = Path(tempfile.mkdtemp(prefix="lugre-test-data-"))
    for p in files:
        rel = p.relative_to(DATA)
        out = tmp / (rel.with_suffix("") if p.suffix == ".gz" else rel)
        out.parent.mkdir(parents=True, exist_ok=True)
        if p.suffix == ".gz":
            with gzip.open(p, "rb") as src, open(out, "wb") as dst:
                shutil.copyfileobj(src, dst)
        else:
            shutil.copyfile(p, out)
    try:
        os.replace(tmp, root)  # another process may have unpacked it meanwhile
    except OSError:
        shutil.rmtree(tmp, ignore_errors=True)
    return root


SHARED = _unpack()
DATASETS = SHARED / "datasets"


def shared_file(*parts: str) -> Path:
    """A file of the test data's ``datasets``; the data is part of the repository, so a
    missing file fails the test."""
    p = DATASETS.joinpath(*parts)
    if not p.exists():
        pytest.fail(f"test dataset {p} is missing: tests/data should hold it")
    return p
