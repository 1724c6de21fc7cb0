"""Test-wide rules.

In CI (``CI`` set, as ``.ci/run`` does) a test that would skip because something CI
installs is missing (the headless browser, the compiled core as a release build,
import-linter) FAILS instead: CI must run every check, and a silent skip would hide a
broken setup. The data the tests read is in the repository (tests/data): no test skips
for want of it.
"""

from __future__ import annotations

import os

import pytest

#: Words in a skip reason that mean "something CI must provide is missing".
_REQUIRED = ("chromium", "compiled core", "release build", "import-linter")


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    outcome = yield
    report = outcome.get_result()
    if not os.environ.get("CI") or not report.skipped:
        return
    reason = str(report.longrepr[-1]) if isinstance(report.longrepr, tuple) else str(
        report.longrepr)
    if any(w in reason for w in _REQUIRED):
        report.outcome = "failed"
        report.longrepr = f"in CI this must not skip: {reason}"
