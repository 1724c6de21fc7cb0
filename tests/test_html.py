"""The HTML pages: what a control engineer reads first, in units, self-contained."""

from __future__ import annotations

import json
import re
import subprocess
import sys

import lugre
import numpy as np
import pytest
from htmlcheck import external_references
from lugre.diagnosis import diagnose
from lugre.diagnosis.synth import concealed
from lugre.html import diagnosis_page, paper_page, plain_text
from lugre.io import write_recording


def hand_built() -> tuple[dict, dict]:
    """A report with every optional key, and figure data for its finding."""
    x = np.linspace(-0.1, 0.2, 400)
    effect = 1.5 * np.sin(2 * np.pi * x / 0.0375 + 2.1)
    rng = np.random.default_rng(1)
    report = {
        "verdict": "The axis has cogging of 1.5 N at a 37.5 mm pitch; add it to the "
                   "feed-forward. Sure: confirmed on the second run.",
        "findings": [{
            "effect": "cogging",
            "parameters": {"amplitude": 1.6, "pitch": 0.0375, "phase": 2.1},
            "where": {"position": [-0.1, 0.2], "time": None, "velocity": None},
            "explained": 0.8,
            "evidence": "A force periodic in position: it lowers the held-out score by "
                        "73442 (chi-square on the coloured noise scale), gains in 9 of 10 "
                        "held-out blocks (p = 1e-9).",
            "uncertainty": {"amplitude": [1.5, 1.7], "pitch": [0.0374, 0.0376],
                            "phase": [None, None]},
            "alternatives": [{"effect": "position_friction",
                              "parameters": {"scale": 1.1},
                              "experiment": "a slow move in the other direction"}],
        }],
        "fit": {"before": {"rms_force": 2.1, "nrmse_force": 0.012},
                "after": {"rms_force": 0.9, "nrmse_force": 0.005},
                "holdout_before": {"rms_force": 2.2, "nrmse_force": 0.013},
                "holdout_after": {"rms_force": 1.0, "nrmse_force": 0.006}},
        "noise": {"rms": 0.8},
        "could_not_reveal": [{"effect": "drift", "smallest": 0.05, "unit": "",
                              "range": [0.0, 20.0], "experiment": "a cold start of 30 min",
                              "text": "the record lasts 20 s"}],
        "base_moves": [{"parameter": "mass", "before": 25.0, "after": 25.4, "unit": "kg",
                        "text": "payload"}],
        "unexplained": {"message": "a 3 N burst stays unexplained.",
                        "where": {"time": [3.0, 3.5], "position": None, "velocity": None}},
        "notes": ["sigma1 is poorly determined by this record."],
        "removed": [{"effect": "spring", "parameters": {"stiffness": 5.0, "x0": 0.0},
                     "evidence": "The model's spring does not match this record.",
                     "gain": 220.0, "p": 1e-4, "positive": 9, "blocks": 10}],
    }
    data = {"effects": [{"x": x, "residual": effect + 0.3 * rng.standard_normal(x.size),
                         "effect": effect, "xlabel": "position [m]"}]}
    return report, data


def text_of(page: str) -> str:
    body = re.sub(r"<style>.*?</style>", " ", page, flags=re.DOTALL)
    body = re.sub(r"<[^>]+>", " ", body)
    return re.sub(r"\s+", " ", body)


def test_hand_built_report_renders_every_optional_key():
    report, data = hand_built()
    page = diagnosis_page(report, data, source="rec.csv", model="m.json", holdout="h.csv")
    text = text_of(page)
    assert external_references(page) == []
    assert text.index("Verdict") < text.index("Findings")
    assert report["verdict"].split(";")[0] in text
    assert "1.5 to 1.7 N" in text and "37.4 to 37.6 mm" in text  # intervals in units
    assert "not determined by this record: determine it with a slow" in text  # phase
    assert "position −100 to 200 mm" in text
    assert "a cold start of 30 min" in text and "the record lasts 20 s" in text
    assert "25 kg" in text and "25.4 kg" in text and "payload" in text
    assert "a 3 N burst stays unexplained." in text and "time 3 to 3.5 s" in text
    assert "sigma1 is poorly determined" in text
    assert "To determine sigma1: short reversals" in text
    assert "a slow move in the other direction" in text
    assert page.count("data:image/png;base64,") == 1  # the finding's own figure
    assert "chi-square" not in text and "score by" not in text
    assert "9 of 10 stretches" in text
    assert text.index("Removed from the model") < text.index("Held-out gain")
    assert "spring does not match this record." in text
    assert "stiffness 5" in text


def test_shares_add_up_to_one_hundred():
    report, data = hand_built()
    text = text_of(diagnosis_page(report, data))
    table = text[text.index("share of the force residual"):text.index("Findings")]
    shares = [int(s) for s in re.findall(r"(\d+) %", table)]
    assert sum(shares) == 100 and len(shares) >= 3


def test_minimal_report_degrades_gracefully():
    page = diagnosis_page({"findings": [], "fit": {}})
    text = text_of(page)
    assert "No missing physics" in text and external_references(page) == []
    page = diagnosis_page({"findings": [], "fit": {}, "unexplained": {"message": "odd."}})
    assert "odd." in text_of(page) and "No missing physics" not in text_of(page)


def test_plain_text_has_no_internal_scores():
    s = plain_text("fitted jointly it lowers the held-out score by 73442 (chi-square on the "
                   "coloured noise scale), gains in 10 of 10 held-out blocks (p = 1e-12).")
    assert "73442" not in s and "chi-square" not in s and "10 of 10" in s


@pytest.fixture(scope="module")
def real():
    rec, believed, _ = concealed("cogging", duration=6.0)
    return rec, believed, diagnose(rec, believed, closed_loop=False)


def test_page_from_a_current_diagnosis(real):
    _, _, d = real
    page = diagnosis_page(d.to_dict(), d.data)
    text = text_of(page)
    assert external_references(page) == []
    assert "cogging" in text and " mm" in text
    assert not re.search(r"\[-?\d+\.\d+, -?\d+\.\d+\]", text)  # no bare ranges
    assert page.count("data:image/png;base64,") >= 4
    assert "chi-square" not in text


def test_diagnose_html_cli(real, tmp_path):
    rec, believed, _ = real
    write_recording(tmp_path / "rec.csv", rec)
    lugre.save_model(believed, tmp_path / "m.json")
    r = subprocess.run([sys.executable, "-m", "lugre", "diagnose", tmp_path / "rec.csv",
                        "--model", tmp_path / "m.json", "--json", tmp_path / "r.json",
                        "--html", tmp_path / "r.html"], capture_output=True, text=True, check=False)
    assert r.returncode == 0, r.stderr
    page = (tmp_path / "r.html").read_text()
    assert external_references(page) == [] and "Verdict" in page
    assert json.loads((tmp_path / "r.json").read_text())["findings"]
    r = subprocess.run([sys.executable, "-m", "lugre", "fit", tmp_path / "rec.csv",
                        "--force-constant", "25", "--no-refine", "--json", tmp_path / "f.json",
                        "--html", tmp_path / "f.html"], capture_output=True, text=True, check=False)
    assert r.returncode == 0, r.stderr
    page = (tmp_path / "f.html").read_text()
    assert external_references(page) == [] and "kg" in page and "N s/m" in page


def test_fit_static_html_cli(tmp_path):
    v = np.concatenate([np.geomspace(1e-3, 0.3, 12), -np.geomspace(1e-3, 0.3, 12)])
    F = np.sign(v) * (28 + 32 * np.exp(-(v / 0.01) ** 2) + 330 * np.abs(v))
    (tmp_path / "p.csv").write_text("v,F\n" + "".join(f"{a:.9g},{b:.9g}\n" for a, b in zip(v, F)))
    r = subprocess.run([sys.executable, "-m", "lugre", "fit-static", tmp_path / "p.csv",
                        "--json", tmp_path / "m.json", "--html", tmp_path / "s.html"],
                       capture_output=True, text=True, check=False)
    assert r.returncode == 0, r.stderr
    text = text_of((tmp_path / "s.html").read_text())
    assert "95 % interval" in text and "Placeholders" in text and " mm/s" in text


def paper_doc() -> dict:
    row = {"truth": 28.7, "paper": 28.5, "estimate": 28.69, "ci95": [28.5, 28.9]}
    return {"table1": {"positive": {"fc": row, "vs": {"truth": 0.01, "paper": 0.0098,
                                                      "estimate": 0.0101,
                                                      "ci95": [0.0095, 0.0105]}},
                       "negative": {"fc": row}},
            "table2": {"sigma0": {"truth": 1e5, "paper": 1.1e5, "estimate": 1.01e5,
                                  "ci95": [0.95e5, 1.05e5]},
                       "sigma1": {"truth": 31.62, "paper": 30.0, "estimate": 31.0,
                                  "ci95": [25.0, 37.0]}}}


def test_paper_page_renders_the_contract_structure():
    page = paper_page(paper_doc())
    text = text_of(page)
    assert external_references(page) == []
    assert "28.7 N" in text and "28.5 to 28.9 N" in text and "10 mm/s" in text
    assert "95000 to 105000 N/m" in text and "25 to 37 N s/m" in text
    assert "Table 1" in text and "Table 2" in text


def test_paper_html_cli(tmp_path):
    r = subprocess.run([sys.executable, "-m", "lugre", "paper", "--out", tmp_path / "p",
                        "--monte-carlo", "0", "--html", tmp_path / "paper.html"],
                       capture_output=True, text=True, check=False)
    assert r.returncode == 0, r.stderr
    text = text_of((tmp_path / "paper.html").read_text())
    assert "Table 1" in text and "fc (v ≥ 0)" in text and "N/m" in text


def test_long_profiles_are_summarised_in_units():
    pos = list(np.linspace(-0.1, 0.2, 25))
    scale = [1.0] * 25
    scale[6] = 1.32
    report = {"findings": [{"effect": "position_friction",
                            "parameters": {"positions": pos, "scale": scale},
                            "where": {"position": [-0.05, -0.03], "time": None,
                                      "velocity": None},
                            "explained": 0.9, "evidence": "friction changes along x."}],
              "fit": {"before": {"rms_force": 2.8, "nrmse_force": 0.025},
                      "after": {"rms_force": 0.23, "nrmse_force": 0.002}}}
    text = text_of(diagnosis_page(report))
    assert "25 values, −100 to 200 mm" in text
    assert "largest change ×1.32 at −25 mm" in text


def test_a_small_share_is_not_written_as_zero():
    """A finding that explains 0.4 % of the residual reads "under 0.5 %", not "0 %"."""
    from lugre import units as U

    assert U.percent(0.004) == "under 0.5 %"
    assert U.percent(0.0004, 1) == "under 0.05 %"
    assert U.percent(0.006) == "1 %"
    assert U.percent(0.0) == "0 %"
    assert U.percent(0.5) == "50 %"


WHERES = [
    None,
    {},
    {"position": [-0.1, 0.2], "time": None, "velocity": None},
    {"velocity": [[-0.05, -0.01], [0.01, 0.04]], "time": [[1.0, 2.0]], "position": []},
    {"velocity": [[float(k), float(k) + 0.5] for k in range(7)]},
    {"direction": {"positive": 137.18, "negative": 2.0, "rest": None}, "threshold": 1.2},
    {"time": [None, 3.0], "velocity": [1, 2, 3], "direction": "forward"},
]


@pytest.mark.parametrize("where", WHERES)
def test_the_page_takes_every_shape_of_where(where):
    """Several velocity ranges, a per-direction rest, open ends: the page says where in
    words and units, never a raw Python structure, and never fails."""
    report, data = hand_built()
    report["findings"][0]["where"] = where
    report["unexplained"]["where"] = where
    text = _words(diagnosis_page(report, data))
    assert "{'" not in text and "[[" not in text
    if isinstance(where, dict) and where.get("direction") and isinstance(where["direction"], dict):
        assert "moving forward 137 N rms" in text


def test_the_page_shows_a_refitted_base():
    report, data = hand_built()
    report["rebased"] = {"moves": [{"name": "positive.hump", "given": 0.0, "refit": 31.5,
                                    "change": 1.1}],
                         "rms_given": 9.0, "rms_refit": 1.0, "text": "the base was far"}
    text = _words(diagnosis_page(report, data))
    assert "Base refitted first" in text and "31.5" in text


def _words(page: str) -> str:
    import html

    return html.unescape(re.sub(r"<[^>]+>", " ", page))


def test_fit_page_shows_what_the_record_determines():
    from lugre.html import fit_page

    doc = lugre.Model.paper().to_dict()
    doc["identification"] = {
        "nrmse_force": 0.004, "summary": "force residual 0.1 N rms against a noise floor of "
        "0.09 N (1.1 times): at the record's noise floor", "far_from_floor": False,
        "parameters": {"positive.hump": {"value": 31.5, "unit": "N", "ci95": [31.0, 32.0],
                                         "determined": True, "how": "wald"},
                       "sigma1": {"value": 3.0, "unit": "N s/m", "ci95": [None, None],
                                  "determined": False, "how": "profile"}}}
    text = _words(fit_page(doc, nrmse={"fitted model": 0.004}))
    assert "What the record determines" in text
    assert "fs - fc (v >= 0)" in text and "open to open N s/m" in text
    doc["identification"]["far_from_floor"] = True
    assert "Check first" in _words(fit_page(doc))


def test_a_verdict_never_says_keep_and_add_together():
    """When the refit does not carry over to the held-out record the verdict says to keep
    the model and check first, and does not also say to add the findings."""
    from types import SimpleNamespace

    from lugre.diagnosis.evidence import verdict

    f = SimpleNamespace(effect="cogging", alternatives=[],
                        parameters={"amplitude": 1.0, "pitch": 0.02, "phase": 0.0})
    dg = SimpleNamespace(findings=[f], removed=[], rebased=None, base_moves=[],
                         unexplained=None,
                         fit={"holdout_before": {"rms_force": 1.0},
                              "holdout_after": {"rms_force": 1.5}})
    text = verdict(dg)
    assert "keep the model as given" in text and "Add it" not in text
    dg.fit["holdout_after"] = {"rms_force": 0.5}
    text = verdict(dg)
    assert "Add it" in text and "keep the model" not in text
