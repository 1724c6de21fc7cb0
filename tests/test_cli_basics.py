"""The command line's basics: --version, help with defaults and an example, progress on
a terminal only, and a light ``import lugre``."""

from __future__ import annotations

import io
import subprocess
import sys
import time

import lugre
import pytest
from lugre._progress import Progress


def run(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "lugre", *args], capture_output=True,
                          text=True, check=False)


def test_version():
    r = run("--version")
    assert r.returncode == 0 and r.stdout.strip() == f"lugre {lugre.__version__}"


@pytest.mark.parametrize("cmd", ["demo", "paper", "fit-static", "fit-dynamic", "fit",
                                 "diagnose", "evaluate"])
def test_help_has_defaults_and_an_example(cmd):
    r = run(cmd, "--help")
    assert r.returncode == 0
    assert "example:" in r.stdout and f"lugre {cmd} " in r.stdout.split("example:")[1]
    assert "(default:" in r.stdout
    assert "--quiet" in r.stdout


def test_progress_is_shown_only_when_enabled_and_for_long_steps():
    out = io.StringIO()
    p = Progress(enabled=True, stream=out, after=0.05)
    with p.step("quick"):
        pass
    with p.step("slow step"):
        time.sleep(0.2)
    text = out.getvalue()
    assert "quick" not in text
    assert "slow step ..." in text and "slow step: done in" in text
    off = io.StringIO()
    with Progress(stream=off, after=0.0).step("not a terminal"):  # StringIO is no tty
        time.sleep(0.05)
    assert off.getvalue() == ""


def test_usage_errors_exit_2_without_traceback(tmp_path):
    r = run("fit", "missing.csv", "--json", str(tmp_path / "no" / "m.json"))
    assert r.returncode == 2 and "Traceback" not in r.stderr and "--json" in r.stderr
    r = run("evaluate", str(tmp_path / "missing.csv"), "--model", "m.json", "--json",
            str(tmp_path / "e.json"))
    assert r.returncode == 1 and "Traceback" not in r.stderr
    assert r.stderr.count("\n") == 1 and "does not exist" in r.stderr


def test_import_lugre_is_light():
    code = ("import sys, time; t = time.process_time(); import lugre; "
            "dt = time.process_time() - t; "
            "heavy = sorted(m for m in ('scipy', 'matplotlib') if m in sys.modules); "
            "print(dt, ','.join(heavy))")
    times = []
    # CPU time of the import (wall-clock time also counts the other work on a shared
    # machine); the best of three
    for _ in range(3):
        r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                           check=True)
        dt, heavy = r.stdout.split()[0], r.stdout.split()[1:]
        assert heavy == [], f"import lugre imports {heavy}"
        times.append(float(dt))
    assert min(times) <= 0.3, times
    # the lazy names still resolve
    # (the diagnosis itself needs no SciPy since issue 28: the modules are the proof)
    lazy = ("import lugre; print(lugre.fit_static.__module__, lugre.Diagnosis.__module__)")
    r = subprocess.run([sys.executable, "-c", lazy], capture_output=True, text=True,
                       check=True)
    assert r.stdout.split() == ["lugre.identify", "lugre.diagnosis.report"]
    with pytest.raises(AttributeError):
        lugre.no_such_name  # noqa: B018
