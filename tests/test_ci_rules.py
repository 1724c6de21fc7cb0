"""The rule of tests/conftest.py: in CI a skip for want of what CI installs fails."""

from __future__ import annotations

from pathlib import Path

import pytest

pytest_plugins = ["pytester"]

CONFTEST = (Path(__file__).parent / "conftest.py").read_text()

SKIPPING = """
import pytest

def test_needs_chromium():
    pytest.skip("no headless chromium found")

def test_optional():
    pytest.skip("pandas is not installed")
"""


@pytest.mark.parametrize("ci", ["", "1"])
def test_skips_for_what_ci_installs_fail_in_ci(pytester, monkeypatch, ci):
    pytester.makeconftest(CONFTEST)
    pytester.makepyfile(SKIPPING)
    if ci:
        monkeypatch.setenv("CI", ci)
    else:
        monkeypatch.delenv("CI", raising=False)
    result = pytester.runpytest("-p", "no:cacheprovider")
    if ci:
        result.assert_outcomes(failed=1, skipped=1)
    else:
        result.assert_outcomes(skipped=2)
