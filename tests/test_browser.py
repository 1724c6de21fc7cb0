"""The HTML pages in a real browser (headless Chromium): each renders to a screenshot that
is not blank, and loading it requests nothing from outside (net log, with every host name
resolving nowhere). Chromium comes from the Debian packages, installed by ``.ci/run``; in
CI its absence fails these tests (tests/conftest.py)."""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from htmlcheck import external_references
from lugre.diagnosis import diagnose
from lugre.diagnosis.synth import concealed
from lugre.html import diagnosis_page, paper_page
from test_html import hand_built, paper_doc

CHROMIUM = next((shutil.which(n) for n in ("chromium", "chromium-browser", "google-chrome")
                 if shutil.which(n)), None)

pytestmark = pytest.mark.skipif(
    CHROMIUM is None, reason="chromium is not installed (apt-get install chromium; .ci/run "
    "installs it)")


def render(page: Path, tmp: Path, width: int = 1000, height: int = 1400) -> tuple[np.ndarray, list[str]]:
    """Screenshot pixels of ``page`` and the URLs Chromium requested while loading it."""
    from matplotlib.image import imread

    shot = tmp / f"{page.stem}-{width}.png"
    netlog = tmp / f"{page.stem}-{width}.netlog.json"
    cmd = [CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
           "--no-first-run", "--disable-background-networking", "--disable-component-update",
           "--disable-sync", "--disable-default-apps", "--disable-extensions",
           "--host-resolver-rules=MAP * ~NOTFOUND", "--proxy-server=http://127.0.0.1:9",
           f"--user-data-dir={tmp / 'profile'}", f"--log-net-log={netlog}",
           f"--window-size={width},{height}", f"--screenshot={shot}", page.as_uri()]
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=120, check=False)
    assert shot.is_file(), r.stderr[-2000:]
    return imread(shot), requested_urls(netlog)


def requested_urls(netlog: Path) -> list[str]:
    """URLs the page requested, from a Chromium net log: the ``URL_REQUEST_START_JOB``
    events made for a document (the browser's own background requests carry the
    initiator ``"not an origin"``; ``file:`` and ``data:`` URLs are not network
    requests)."""
    text = netlog.read_text(errors="replace")
    try:
        doc = json.loads(text)
    except ValueError:  # the browser may leave the closing brackets out
        doc = json.loads(text.rstrip().rstrip(",") + "]}")
    start = doc["constants"]["logEventTypes"]["URL_REQUEST_START_JOB"]
    urls = []
    for ev in doc.get("events", []):
        p = ev.get("params") or {}
        url = p.get("url")
        if (ev.get("type") == start and isinstance(url, str)
                and p.get("initiator") != "not an origin"
                and not url.startswith(("data:", "file:"))):
            urls.append(url)
    return urls


def not_blank(pixels: np.ndarray) -> bool:
    gray = pixels[..., :3].mean(axis=-1) if pixels.ndim == 3 else pixels
    return float(gray.std()) > 0.02


@pytest.fixture(scope="module")
def pages(tmp_path_factory):
    d = tmp_path_factory.mktemp("pages")
    report, data = hand_built()
    (d / "hand_built.html").write_text(diagnosis_page(report, data))
    rec, believed, _ = concealed("cogging", duration=6.0)
    dg = diagnose(rec, believed, closed_loop=False)
    (d / "diagnosis.html").write_text(diagnosis_page(dg.to_dict(), dg.data))
    (d / "paper.html").write_text(paper_page(paper_doc()))
    from lugre import fit_model
    from lugre.diagnosis.fitreport import identification
    from lugre.html import fit_page

    model, fit = fit_model(rec, force_constant=believed.force_constant)
    doc = model.replace(identification=identification(fit, model, 0.01)).to_dict()
    (d / "fit.html").write_text(fit_page(doc, rec, nrmse={"fitted model": 0.01}))
    return d


@pytest.mark.parametrize("name", ["hand_built", "diagnosis", "paper", "fit"])
@pytest.mark.parametrize("width", [1000, 390])  # a laptop and a phone
def test_page_renders_and_fetches_nothing(pages, name, width, tmp_path):
    page = pages / f"{name}.html"
    assert external_references(page.read_text()) == []
    pixels, urls = render(page, tmp_path, width=width)
    assert not_blank(pixels)
    assert urls == []


def test_the_checks_can_fail(tmp_path):
    """A blank page is seen as blank, a page with an outside image as fetching it."""
    blank = tmp_path / "blank.html"
    blank.write_text("<!DOCTYPE html><html><body style='background:#fff'></body></html>")
    pixels, urls = render(blank, tmp_path)
    assert not not_blank(pixels) and urls == []
    fetching = tmp_path / "fetching.html"
    fetching.write_text("<!DOCTYPE html><html><body><h1>x</h1>"
                        "<img src='http://example.invalid/a.png'></body></html>")
    assert external_references(fetching.read_text()) == ["http://example.invalid/a.png"]
    _, urls = render(fetching, tmp_path)
    assert any("example.invalid" in u for u in urls)
