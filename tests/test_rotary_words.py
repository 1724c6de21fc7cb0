"""A rotary axis speaks rad, rad/s, N m, kg m^2 and N m/A, torque and inertia, in every
text a user reads (CLI output, the diagnosis's summary, verdict and evidence, the pages);
a linear axis keeps N and mm (CONTRACT, "Rotary axes")."""

from __future__ import annotations

import json
import re
import subprocess
import sys
from html.parser import HTMLParser
from pathlib import Path

import lugre
import numpy as np
import pytest
from lugre.diagnosis.evaluation import level_shift_text
from lugre.html import diagnosis_page
from lugre.io import read_recording, write_recording

LUGRE = [sys.executable, "-m", "lugre"]

#: A linear unit or word in a text: N (not N m), mm, kg (not kg m^2), N/A, N s/m, N/m,
#: m/s (not rad/s), a bare m, um, force, mass, payload, millimetres, micrometres.
LINEAR = re.compile(
    r"(?<![\w/^])N\b(?! m\b)|\bmm\b|\bkg\b(?! m\^?2| m²)|N/A\b|N s/m|N/m\b|(?<![\w])m/s\b"
    r"|(?<!N )(?<![\w/^.])m\b(?![\w/^²])|\bum\b|µm"
    r"|(?i:(?<![-\w])(?:forces?|mass(?:es)?|payloads?|newtons?|micromet\w*|millimet\w*)\b)")

#: Options and names that hold a linear word but are no unit of the axis.
_NOT_WORDS = re.compile(r"--force-constant|force_constant|--mass\b|\bmass\b(?==)")


def linear_words(text: str) -> list[str]:
    """Each linear unit or word in ``text``, with its context."""
    text = _NOT_WORDS.sub("", text)
    return [text[max(0, m.start() - 50):m.end() + 20] for m in LINEAR.finditer(text)]


class _Visible(HTMLParser):
    def __init__(self) -> None:
        super().__init__(convert_charrefs=True)
        self.out: list[str] = []
        self._skip = 0

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        self._skip += tag in ("script", "style")
        self.out.extend(v for k, v in attrs if k in ("title", "alt") and v)

    def handle_endtag(self, tag: str) -> None:
        self._skip -= tag in ("script", "style")

    def handle_data(self, data: str) -> None:
        if not self._skip:
            self.out.append(data)


def visible(page: str) -> str:
    """The text a reader sees on a page (and its titles)."""
    p = _Visible()
    p.feed(page)
    return " ".join(p.out)


def _model(kind: str = "rotary", effects: list | None = None) -> lugre.Model:
    axis = ({"kind": "rotary", "inertia": 0.02, "torque_constant": 0.5} if kind == "rotary"
            else {"mass": 0.02, "force_constant": 0.5})
    side = {"fc": 0.3, "fs": 0.5, "sigma2": 0.05, "vs": 0.05}
    return lugre.Model.from_dict({
        "axis": axis,
        "friction": {"model": "lugre", "sigma0": 2e3, "sigma1": 0.3, "positive": side,
                     "negative": dict(side)},
        "effects": effects or [],
        "controller": {"type": "pid", "kp": 40.0, "ki": 200.0, "kd": 1.5, "rate_hz": 1e3}})


def _recording(model: lugre.Model, seed: int) -> lugre.Recording:
    t = np.arange(0.0, 20.0, 1e-3)
    x_ref = 1.0 * np.sin(2 * np.pi * 0.2 * t) + 0.2 * np.sin(2 * np.pi * 1.3 * t)
    r = lugre.simulate(model, t, x_ref=x_ref)
    return lugre.Recording.from_simulation(r, x_ref=x_ref, quantum=1e-5,
                                           current_noise=5e-3, seed=seed)


#: The record's missing physics: a cogging of 0.05 N m at a 0.3 rad pitch.
COGGING = {"effect": "cogging", "amplitude": 0.05, "pitch": 0.3, "phase": 0.2}


@pytest.fixture(scope="module")
def records(tmp_path_factory: pytest.TempPathFactory) -> Path:
    d = tmp_path_factory.mktemp("rotary")
    truth = _model(effects=[COGGING])
    write_recording(_recording(truth, 1), d / "rec.csv")
    write_recording(_recording(truth, 2), d / "hold.csv")
    return d


def _run(*args: object) -> subprocess.CompletedProcess[str]:
    r = subprocess.run([*LUGRE, *map(str, args)], capture_output=True, text=True,
                       check=False)
    assert r.returncode == 0, r.stderr
    return r


@pytest.fixture(scope="module")
def cli(records: Path) -> dict[str, str]:
    d = records
    fit = _run("fit", d / "rec.csv", "--x-unit", "rad", "--force-constant", "0.5",
               "--json", d / "M.json", "--html", d / "P.html")
    diag = _run("diagnose", d / "rec.csv", "--model", d / "M.json", "--holdout",
                d / "hold.csv", "--json", d / "R.json", "--html", d / "P2.html")
    ev = _run("evaluate", d / "hold.csv", "--model", d / "M.json", "--json", d / "E.json")
    return {"fit": fit.stdout + fit.stderr, "diagnose": diag.stdout + diag.stderr,
            "evaluate": ev.stdout + ev.stderr,
            "fit page": visible((d / "P.html").read_text()),
            "diagnosis page": visible((d / "P2.html").read_text())}


def test_cli_speaks_the_rotary_axis(cli: dict[str, str]) -> None:
    for name, text in cli.items():
        assert linear_words(text) == [], name
    assert "inertia" in cli["fit"] and "kg m^2" in cli["fit"]
    assert "torque constant 0.5 N m/A" in cli["fit"]
    assert "N m s/rad" in cli["fit"] and "rad/s" in cli["fit"]
    assert "torque residual" in cli["fit"]
    assert "cogging (amplitude" in cli["diagnose"] and " rad" in cli["diagnose"]
    assert "N m rms" in cli["diagnose"]
    assert re.search(r"pitch of 0\.(?:29|30)\d* rad", cli["diagnose"]), cli["diagnose"]
    assert "rms torque residual" in cli["evaluate"] and " N m," in cli["evaluate"]
    assert "inertia" in cli["fit page"] and "torque constant" in cli["fit page"]
    assert "N m" in cli["diagnosis page"] and "rad" in cli["diagnosis page"]


def test_report_keys_stay_and_axis_says_the_units(cli: dict[str, str],
                                                  records: Path) -> None:
    report = json.loads((records / "R.json").read_text())
    assert report["axis"]["kind"] == "rotary" and report["axis"]["force"] == "N m"
    assert report["findings"][0]["effect"] == "cogging"
    assert {"verdict", "findings", "fit", "could_not_reveal"} <= set(report)
    for entry in report["could_not_reveal"]:
        assert linear_words(entry["text"]) == [], entry
        assert linear_words(entry.get("experiment") or "") == [], entry
    model = json.loads((records / "M.json").read_text())
    assert set(model["axis"]) >= {"kind", "inertia", "torque_constant"}
    assert linear_words(model["identification"]["summary"]) == []


def test_python_api_speaks_the_rotary_axis(records: Path) -> None:
    rec = read_recording(records / "rec.csv", x_unit="rad")
    hold = read_recording(records / "hold.csv", x_unit="rad")
    dg = lugre.diagnose(rec, _model(), holdout=hold)
    texts = {"summary": dg.summary(), "verdict": dg.verdict,
             **{f"evidence {k}": f.evidence for k, f in enumerate(dg.findings)},
             **{f"hidden {k}": h["text"] for k, h in enumerate(dg.could_not_reveal)}}
    for name, text in texts.items():
        assert linear_words(text) == [], name
    assert "N m" in dg.summary() and "rad" in dg.summary()
    ev = lugre.evaluate(hold, _model())
    assert linear_words(level_shift_text(ev.get("level_shift")) or "") == []
    page = visible(diagnosis_page(dg.to_dict(), dg.data))
    assert linear_words(page) == []


def test_an_inertia_effect_is_said_as_inertia(records: Path) -> None:
    # the model holds an inertia (a rotary axis's name of the mass effect) the record
    # does not: the diagnosis says inertia and kg m^2, never mass or kg
    given = _model(effects=[COGGING, {"effect": "inertia", "delta": 0.006}])
    assert given.effects[-1]["effect"] == "mass"  # (read as the mass effect)
    rec = read_recording(records / "rec.csv", x_unit="rad")
    dg = lugre.diagnose(rec, given)
    text = dg.summary()
    assert linear_words(text) == [], text
    assert "inertia" in text
    page = visible(diagnosis_page(dg.to_dict(), dg.data))
    assert linear_words(page) == []


def test_a_linear_axis_keeps_newtons_and_millimetres(tmp_path: Path) -> None:
    m = _model("linear", effects=[])
    truth = _model("linear", effects=[COGGING])
    rec = _recording(truth, 3)
    dg = lugre.diagnose(rec, m)
    text = dg.summary()
    assert " N rms" in text and " mm" in text and "Force residual" in text
    assert "N m" not in text and "rad/s" not in text and "torque" not in text
    write_recording(rec, tmp_path / "rec.csv")
    lugre.save_model(m, tmp_path / "m.json")
    out = _run("evaluate", tmp_path / "rec.csv", "--model", tmp_path / "m.json",
               "--json", tmp_path / "e.json").stdout
    assert re.search(r"rms force residual [0-9.]+ N, nrmse", out), out


def test_units_words_on_each_axis() -> None:
    from lugre import units as U

    linear = "a constant force of 1 N, a payload, the mass, --force-constant"
    assert U.words(linear) == linear
    assert U.micro(3.2e-6) == "3.2 um"
    with U.axis("rotary"):
        assert U.words(linear) == ("a constant torque of 1 N, a load inertia, the "
                                   "inertia, --force-constant")
        assert U.words("Force residual, a mass") == "Torque residual, an inertia"
        assert U.micro(3.2e-6) == "3.2 µrad"
        assert U.constant_words() == "torque constant"
