"""The ``lugre fit`` command on a record whose fit sets a load aside (a spring, a
drag): what it says, the model file and the page, checked the same way for each."""

from __future__ import annotations

import json
from pathlib import Path

from lugre import write_recording
from lugre.io import Recording


def check_fit_command(tmp_path: Path, capsys, record: dict, force_constant: float,
                      effect: str, words: str, unit: str) -> None:
    """Run ``lugre fit`` on ``record`` and check that it sets ``effect`` aside: the
    command says so in ``words`` with ``unit``, the file lists it under
    ``identification.set_aside`` and holds no effect, the page opens with "Check
    first." and shows it set aside."""
    from lugre.cli import main

    write_recording(Recording(**record), tmp_path / "rec.csv")
    out, page = tmp_path / "fitted.json", tmp_path / "fit.html"
    code = main(["fit", str(tmp_path / "rec.csv"), "--force-constant", str(force_constant),
                 "--json", str(out), "--html", str(page)])
    assert code == 0 and out.exists()
    said = capsys.readouterr().out
    assert words in said and unit in said
    assert f"lugre fit --effects {effect} keeps it in" in said
    doc = json.loads(out.read_text())
    assert not doc.get("effects")
    assert [e["effect"] for e in doc["identification"]["set_aside"]] == [effect]
    html = page.read_text()
    assert "Check first." in html and f"{effect} (set aside)" in html and unit in html
