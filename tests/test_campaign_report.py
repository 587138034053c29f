"""The campaign report (rigdata.campaign.report, content, render): files, self-contained HTML, verdicts,
calibration sentences and failed recordings, on a CampaignResult built by hand from the campaign's
dataclasses.
"""

from __future__ import annotations

import base64
import dataclasses
import itertools
import json
import math
import re
from html import unescape
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from rigdata.campaign.budget import Budget
from rigdata.campaign.calibration import Calibration, Estimate
from rigdata.campaign.content import uncertainty, value, verdict
from rigdata.campaign.report import write_report
from rigdata.campaign.result import TABLE_COLUMNS, CampaignResult, EngineComparison, RecordingResult
from rigdata.campaign.spec import CampaignSpec, Parameter
from rigdata.conditioning import Conditioning
from rigdata.validation import as_scene

K = 1.959963984540054  # k of 95 % coverage
ENGINES = ("reference", "exudyn")
PARAMETER = Parameter("f", ("joint.pairs.input_spider.friction_coefficient",), 0.2, (0.0, 0.6))
REJECTION = ("reject the model at the 5 % level: a model-form error, not absorbed into the parameters' "
             "uncertainty")
FIGURES = ("efficiency.png", "model_error.png", "budget.png", "residuals.png")


@pytest.fixture(scope="module")
def scene():
    """The rig's scene (the report never reads it; CampaignSpec holds one)."""
    return as_scene("rig")


def _budget(u_d: float) -> Budget:
    """A budget whose u_input is its parameters' part alone (0.001) and no shared covariance."""
    return Budget(u_d, 0.001, 0.001, 0.0, 2e-9, 1e-11, 0.0, {"f": -0.05}, {}, 3e-6)


def _recording(index: int, label: str, use: str, error: float, synthetic: bool = False) -> RecordingResult:
    """A compared recording with D = 0.97, u_D = 0.002 and E = ``error`` on the first engine."""
    b = _budget(0.002)
    u_num = 1e-11
    u_val = b.u_val(u_num)
    s = 0.97 + error
    first = EngineComparison(ENGINES[0], "ok", None, s, u_num, error, u_val,
                             (error - K * u_val, error + K * u_val), abs(error) > K * u_val)
    second = EngineComparison(ENGINES[1], "ok", None, s - 2e-5, 7e-5, error - 2e-5, math.hypot(u_val, 7e-5),
                              None, None, -2e-5)
    provenance = {"format": "csv"}
    if synthetic:
        provenance["synthetic"] = {"synthetic": "true", "generator": "rigdata.synthetic 1", "settings": "{}"}
    return RecordingResult(index, label, Path(f"/data/{label}"), "0" * 64, use, 20.0, "ok", None,
                           {"speed_in": 6.0, "speed_in_rpm": 57.3, "torque_in": 2.0, "torque_out": 1.95,
                            "revolutions": 10}, 0.97, 0.002, (), K, b,
                           {ENGINES[0]: first, ENGINES[1]: second}, provenance)


def _failed(index: int) -> RecordingResult:
    """A validation recording whose first engine's run failed."""
    failed = EngineComparison(ENGINES[0], "failed", "Newton iterations did not converge", None, None)
    return RecordingResult(index, "broken.csv", Path("/data/broken.csv"), "1" * 64, "validation", 25.0,
                           "model", "reference: failed: Newton iterations did not converge",
                           {"speed_in_rpm": 50.0}, 0.96, 0.003, (), K, None, {ENGINES[0]: failed})


def _calibration(rejected: bool) -> Calibration:
    """A one-parameter fit on recordings 1 and 2, rejected or not by its chi-square."""
    residuals = (2.5, -2.0) if rejected else (0.5, -0.3)
    chi2 = float(np.sum(np.square(residuals)))
    p = float(stats.chi2.sf(chi2, 1))
    assert (p < 0.05) == rejected
    return Calibration((Estimate("f", 0.25, 0.01, True, False, (0.0, 0.6)),), np.array([[1e-4]]),
                       np.array([[1.0]]), (), (1, 2), residuals, (0.002, 0.002), chi2, 1, p, rejected, 6,
                       "`ftol` termination condition is satisfied.")


def _result(scene, *, calibrated: bool = True, rejected: bool = True,
            synthetic: bool = False) -> CampaignResult:
    """Two calibration recordings (the first with a large E), a resolvable and an unresolvable validation
    recording and a failed one.
    """
    spec = CampaignSpec(Path("campaign.toml"), "bench test", scene, "rig", ENGINES, 0.95,
                        (PARAMETER,) if calibrated else (), (), (), Conditioning(), 100, 0, 0)
    recordings = (_recording(1, "cal_big.csv", "calibration", 0.02, synthetic),
                  _recording(2, "cal_small.csv", "calibration", -0.001),
                  _recording(3, "val_resolvable.csv", "validation", 0.012),
                  _recording(4, "val_quiet.csv", "validation", 0.001),
                  _failed(5))
    cal = _calibration(rejected) if calibrated else None
    values = (0.25,) if calibrated else ()
    return CampaignResult(spec, recordings, cal, values, K, None,
                          {"measure": 1.0, "calibrate": 2.0, "validate": 3.0, "model_runs": 10,
                           "model_runs_reused": 4},
                          {"python": "3.11", "packages": {"numpy": "2"}, "engines": {}})


@pytest.fixture(scope="module")
def report(scene, tmp_path_factory):
    """The report of the rejected, calibrated campaign: (files, report.md, report.html)."""
    out = tmp_path_factory.mktemp("report")
    (out / "runs.jsonl").write_text("journal\n")
    files = write_report(_result(scene), out)
    md = files["report.md"].read_text(encoding="utf-8")
    return files, md, files["report.html"].read_text(encoding="utf-8")


def _md_row(md: str, label: str) -> list[str]:
    """The cells of the comparison table's row of recording ``label`` (the first table row naming it)."""
    line = next(line for line in md.splitlines() if line.startswith(f"| {label} | "))
    return [cell.strip() for cell in line.strip("|").split("|")]


def _html_row(html: str, label: str) -> str:
    """The first table row of recording ``label`` in the HTML."""
    return re.search(rf"<tr><td>{re.escape(label)}</td>.*?</tr>", html).group(0)


def test_every_file_written(report):
    """results.json, results.csv, the four figures, report.md and report.html are written; the journal
    beside them is kept."""
    files, _, _ = report
    names = {"results.json", "results.csv", *FIGURES, "report.md", "report.html"}
    assert set(files) == names
    assert all(p.is_file() and p.stat().st_size > 0 for p in files.values())
    assert all(files[name].read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" for name in FIGURES)
    assert (files["report.md"].parent / "runs.jsonl").read_text() == "journal\n"


def test_results_files_are_the_result(report, scene):
    """results.json is the result's as_dict and results.csv its table's columns, one row per recording."""
    files, _, _ = report
    expected = json.loads(json.dumps(_result(scene).as_dict()))
    assert json.loads(files["results.json"].read_text()) == expected
    table = pd.read_csv(files["results.csv"])
    assert list(table.columns) == list(TABLE_COLUMNS)
    assert list(table["label"]) == [r["label"] for r in expected["recordings"]]


def test_html_is_self_contained(report):
    """No external reference in the HTML; every image is an inline PNG data URI, one per figure."""
    _, _, html = report
    assert 'src="http' not in html and 'href="http' not in html
    assert re.findall(r'(?:src|href)="(?!data:image/png;base64,)', html) == []
    images = re.findall(r"<img [^>]*>", html)
    assert len(images) == len(FIGURES)
    for tag in images:
        data = re.search(r'src="data:image/png;base64,([^"]+)"', tag).group(1)
        assert base64.b64decode(data)[:8] == b"\x89PNG\r\n\x1a\n"
    assert "<link" not in html and "<script" not in html


def test_markdown_links_each_figure(report):
    """report.md links every figure it wrote by file name."""
    _, md, _ = report
    for name in FIGURES:
        assert f"]({name})" in md


def _md_alignments(md: str) -> list[list[tuple[str, bool]]]:
    """Each markdown table's (header, right-aligned) pairs, read from its header and rule lines."""
    lines = md.splitlines()
    tables = []
    for head, rule in itertools.pairwise(lines):
        if head.startswith("| ") and rule.startswith("|---"):
            headers = [cell.strip() for cell in head.strip("|").split("|")]
            tables.append(list(zip(headers, [r == "---:" for r in rule.strip("|").split("|")], strict=True)))
    return tables


def _html_alignments(page: str) -> list[list[tuple[str, bool]]]:
    """Each HTML table's (header, numeric) pairs, read from its <th> classes."""
    return [[(unescape(h), c == "num") for c, h in re.findall(r'<th class="(\w+)">(.*?)</th>', head)]
            for head in re.findall(r"<thead><tr>(.*?)</tr></thead>", page)]


def test_markdown_right_aligns_the_numeric_columns(report):
    """report.md right-aligns exactly the columns report.html marks as numbers: in the comparison table
    every column but recording, use and verdict."""
    _, md, page = report
    tables = _md_alignments(md)
    assert tables == _html_alignments(page)
    comparison = dict(next(t for t in tables if ("verdict", False) in t))
    assert [h for h, right in comparison.items() if not right] == ["recording", "use", "verdict"]


def test_resolvable_recording_shows_as_such(report):
    """The validation recording with |E| > k u_val reads "resolvable model error" (red cell), the other
    "not resolvable"."""
    _, md, html = report
    assert _md_row(md, "val_resolvable.csv")[-1] == "**resolvable model error**"
    assert _md_row(md, "val_quiet.csv")[-1] == "not resolvable"
    assert '<td class="resolvable">resolvable model error</td>' in _html_row(html, "val_resolvable.csv")
    assert '<td class="not-resolvable">not resolvable</td>' in _html_row(html, "val_quiet.csv")


@pytest.mark.parametrize("label", ["cal_big.csv", "cal_small.csv"])
def test_calibration_recording_gets_no_validation_verdict(report, label):
    """A calibration recording is marked as such, even with |E| > k u_val: no validation verdict."""
    _, md, html = report
    assert _md_row(md, label)[-1] == "calibration (not a validation)"
    row = _html_row(html, label)
    assert '<td class="calibration">calibration (not a validation)</td>' in row
    assert "resolvable" not in row.replace('class="calibration"', "")


def test_verdict_of_a_calibration_recording_with_a_large_error(scene):
    """verdict() gives a calibration recording whose first engine calls E resolvable no validation verdict."""
    rec = _result(scene).recordings[0].as_dict()
    assert rec["resolvable"] is True
    assert verdict(rec) == ("calibration (not a validation)", "calibration")


@pytest.mark.parametrize("rejected", [True, False], ids=["rejected", "not-rejected"])
def test_rejection_sentence_exactly_when_rejected(scene, tmp_path, rejected):
    """The model-form sentence appears in md and html exactly when the chi-square test rejects the fit."""
    files = write_report(_result(scene, rejected=rejected), tmp_path)
    for name in ("report.md", "report.html"):
        text = files[name].read_text(encoding="utf-8")
        assert (REJECTION in text) == rejected
        assert ("do not reject the model at the 5 % level" in text) == (not rejected)


def test_no_calibration_no_residuals(scene, tmp_path):
    """Without a calibration no residuals figure is written (a stale one is removed) and the report says
    that no calibration was made."""
    write_report(_result(scene), tmp_path)
    assert (tmp_path / "residuals.png").is_file()
    files = write_report(_result(scene, calibrated=False), tmp_path)
    assert "residuals.png" not in files
    assert not (tmp_path / "residuals.png").exists()
    for name in ("report.md", "report.html"):
        text = files[name].read_text(encoding="utf-8")
        assert "No calibration was made" in text
        assert "residuals.png" not in text
    assert len(re.findall(r"<img ", files["report.html"].read_text(encoding="utf-8"))) == len(FIGURES) - 1


def test_failed_recording_with_its_reason(report):
    """A recording whose model run failed is listed with its status and reason, without a verdict."""
    _, md, html = report
    failed = md.split("## Failed recordings", 1)[1].split("##", 1)[0]
    assert "`broken.csv` (model): reference: failed: Newton iterations did not converge" in failed
    assert _md_row(md, "broken.csv")[-1] == "no comparison (model)"
    assert "<code>broken.csv</code> (model): reference: failed: Newton iterations did not converge" in html


def test_synthetic_banner_only_for_synthetic_recordings(scene, tmp_path, report):
    """SYNTHETIC DATA heads the report when a recording's provenance says synthetic, and only then."""
    _, md, html = report
    assert "SYNTHETIC" not in md and "SYNTHETIC" not in html
    files = write_report(_result(scene, synthetic=True), tmp_path)
    md = files["report.md"].read_text(encoding="utf-8")
    assert "**SYNTHETIC DATA** - 1 of 5 recordings" in md
    html = files["report.html"].read_text(encoding="utf-8")
    assert '<p class="banner"><strong>SYNTHETIC DATA</strong>' in html


def test_comparison_numbers_follow_their_uncertainty(report):
    """In the comparison table u_val shows two significant digits and S, D, E its decimals: u_val =
    sqrt(0.001^2 + 0.002^2) = 0.0022, so four decimals."""
    _, md, _ = report
    cells = _md_row(md, "val_resolvable.csv")
    assert cells[5:8] == ["0.9820", "0.9700", "0.0120"]
    assert cells[11] == "0.0022"


@pytest.mark.parametrize(("u", "text"), [(0.0023149, "0.0023"), (0.001, "0.0010"), (6.31e-12, "6.3e-12"),
                                         (0.0, "0"), (None, "-"), (math.nan, "-"), (12.3, "12")])
def test_uncertainty_two_significant_digits(u, text):
    """Uncertainties show two significant digits, trailing zeros kept."""
    assert uncertainty(u) == text


@pytest.mark.parametrize(("x", "u", "text"), [(0.98227, 0.0023, "0.9823"), (0.98227, 0.0999, "0.98"),
                                              (0.98227, 0.099, "0.982"), (0.98227, None, "0.9823"),
                                              (-1.76e-5, 7.0e-5, "-0.000018"), (3.0, 1e-30, "3.0000000000")])
def test_value_matches_the_decimals_of_its_uncertainty(x, u, text):
    """A value shows the decimals of its uncertainty at two significant digits (0.0999 rounds to 0.10),
    at most MAX_DECIMALS; without one, four decimals."""
    assert value(x, u) == text


def test_engines_table_compares_each_engine_with_the_first(report):
    """The engines table gives each engine's S and u_num and the second's difference from the first."""
    _, md, _ = report
    engines = md.split("## Engines", 1)[1].split("##", 1)[0]
    row = _md_row(engines, "val_resolvable.csv")
    assert row == ["val_resolvable.csv", "0.9820", "1.0e-11", "0.9820", "7.0e-05", "-0.000020", "yes"]


def test_report_of_a_failed_calibration_says_so(scene, tmp_path):
    """A calibration that failed is reported with its reason and the initial values used."""
    result = dataclasses.replace(_result(scene), calibration=None, parameter_values=(0.2,),
                                 calibration_error="recording 1 at f = 0.6: the model ended locked: stuck")
    files = write_report(result, tmp_path)
    md = files["report.md"].read_text(encoding="utf-8")
    assert "**The calibration failed:** recording 1 at f = 0.6: the model ended locked: stuck." in md
    assert "residuals.png" not in files
