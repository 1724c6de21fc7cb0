"""The package's layers: ``import lugre`` leaves the NumPy twin alone, and the import
contracts of ``pyproject.toml`` (``[tool.importlinter]``) hold."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import lugre
import pytest

ROOT = Path(__file__).resolve().parents[1]


def _env() -> dict[str, str]:
    """The environment with the directory that holds the imported ``lugre`` first on the
    path (the working tree's python/, or the installed wheel's site-packages)."""
    env = dict(os.environ)
    where = str(Path(lugre.__file__).resolve().parents[1])
    env["PYTHONPATH"] = os.pathsep.join([where, env.get("PYTHONPATH", "")]).rstrip(os.pathsep)
    return env


def test_import_lugre_does_not_load_the_twin():
    code = ("import lugre, sys; "
            "print(any(m.startswith('lugre.reference') for m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         env=_env(), check=True)
    assert out.stdout.strip() == "False"


def test_the_diagnosis_runs_without_the_twin():
    """The diagnosis's default kernels are the core's: preparing a record loads no twin."""
    code = ("import sys, numpy as np, lugre; "
            "from lugre.diagnosis import residual as R; "
            "t = np.arange(0, 1, 1e-3); m = lugre.Model.paper(); "
            "r = lugre.simulate(m, t, 0.01 * np.sin(6.0 * t)); "
            "R.prepare(lugre.Recording(t=t, x=r.x, F=r.force), m); "
            "print(any(m.startswith('lugre.reference') for m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         env=_env(), check=True)
    assert out.stdout.strip() == "False"


@pytest.mark.skipif(shutil.which("lint-imports") is None, reason="import-linter is not installed")
def test_import_contracts_hold():
    out = subprocess.run(["lint-imports", "--no-cache"], capture_output=True, text=True,
                         check=False, cwd=ROOT, env=_env())
    assert out.returncode == 0, out.stdout + out.stderr
