"""Where the tests find ``../shared`` (the datasets written by an independent plant and
the real EMPS records), next to the repository."""

from __future__ import annotations

from pathlib import Path

import pytest

SHARED = Path(__file__).resolve().parents[1].parent / "shared"
DATASETS = SHARED / "datasets"


def shared_file(*parts: str) -> Path:
    """A file of ``../shared/datasets``; skips (fails in CI) when it is absent."""
    p = DATASETS.joinpath(*parts)
    if not p.exists():
        pytest.skip(f"shared dataset {p} is absent (expected ../shared next to the repo)")
    return p
