"""Hardening: bad input at every entry point (the cases of ``tests/bad_inputs.py``, one
test each), outputs written atomically when a command fails or is interrupted half-way, and no NaN
or infinite efficiency printed for a failed run."""

from __future__ import annotations

import contextlib
import io
import json
import math
import os
import re
import traceback
import warnings
from pathlib import Path

import pytest
from bad_inputs import CASES, DIRECTORY, ENTRY_POINTS, MARKER, Case

from cardan_exudyn import outputs as cio
from cardan_exudyn.cli import main
from cardan_exudyn.engines import run
from reference.results.result import Result
from reference.results.summary import Status, Summary

#: Non-finite numbers as a command would print them (``nan``, ``inf``, ``-inf``, ``infinity``).
NON_FINITE = re.compile(r"(?<![\w.])[-+]?(nan|inf|infinity)(?![\w])", re.IGNORECASE)


# Running one case and saying what is wrong with its outcome


def materialise(case: Case, folder: Path) -> Path:
    """Create the case's files and, when the case has one, its pre-populated output; returns the
    output's path (``{out}``)."""
    for name, content in case.files.items():
        path = folder / name
        if content is DIRECTORY:
            path.mkdir(parents=True)
        elif isinstance(content, bytes):
            path.write_bytes(content)
        else:
            path.write_text(content, encoding="utf-8")
    out = folder / "out"
    if case.out == "folder":
        out.mkdir()
        (out / "marker.txt").write_text(MARKER, encoding="utf-8")
    elif case.out == "file":
        out.write_text(MARKER, encoding="utf-8")
    return out


def untouched(out: Path, kind: str) -> list[str]:
    """What changed in the output since :func:`materialise` (none: it is intact, with no
    temporary sibling)."""
    siblings = [p.name for p in out.parent.iterdir() if p.name.startswith(f".{out.name}")]
    if siblings:
        return [f"temporary files left next to the output: {siblings}"]
    if kind == "file":
        if not out.is_file() or out.read_text(encoding="utf-8") != MARKER:
            return ["the output file was replaced or changed"]
        return []
    if not out.is_dir():
        return ["the output folder is gone or replaced"]
    entries = sorted(p.name for p in out.iterdir())
    if entries != ["marker.txt"] or (out / "marker.txt").read_text(encoding="utf-8") != MARKER:
        return [f"the output folder changed: it holds {entries}"]
    return []


def run_cli(argv: list[str]) -> tuple[int, str, str]:
    """``cardan argv`` in this process: exit status, stdout and stderr. An exception the command
    lets through is printed as the interpreter would (a traceback) with exit status 1."""
    stdout, stderr = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(stdout), contextlib.redirect_stderr(stderr), warnings.catch_warnings():
        try:
            status = main(argv)
        except SystemExit as exc:  # argparse
            status = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
        except BaseException:  # noqa: BLE001 - the point is to see what escapes
            traceback.print_exc(file=stderr)
            status = 1
    return int(status if status is not None else 0), stdout.getvalue(), stderr.getvalue()


def non_finite(text: str) -> list[str]:
    """Non-finite numbers in printed output, leaving out a friction loop gain (a reason's
    ``loop gain inf`` says why a run locked; it is not a result)."""
    text = re.sub(r"loop gain\)?:? ?[-+]?inf", "", text, flags=re.IGNORECASE)
    return [m.group(0) for m in NON_FINITE.finditer(text)]


def _refuse_constant(name: str) -> None:
    raise ValueError(f"{name} in the JSON")


def cli_problems(case: Case, status: int, stdout: str, stderr: str) -> list[str]:
    """Exit status, traceback, one line on stderr and nothing on stdout for bad input; no
    non-finite number and strict JSON for a run; the key word in the message."""
    problems = []
    if status != case.expect:
        problems.append(f"exit status {status}, expected {case.expect}")
    if "Traceback (most recent call last)" in stderr:
        problems.append("traceback")
    if case.expect == 2:
        lines = [line for line in stderr.splitlines() if line.strip()]
        if len(lines) != 1:
            problems.append(f"{len(lines)} lines on stderr, expected one")
        if stdout.strip():
            problems.append("output on stdout")
        text = stderr
    else:
        text = stdout + stderr
        bad = non_finite(text)
        if bad:
            problems.append(f"non-finite numbers printed: {bad[:3]}")
        if "--json" in case.argv:
            try:
                json.loads(stdout, parse_constant=_refuse_constant)
            except ValueError as exc:
                problems.append(f"stdout is not strict JSON: {exc}")
    if case.match.lower() not in text.lower():
        problems.append(f"message lacks {case.match!r}: {text.strip()[:300]!r}")
    return problems


def call_problems(case: Case, folder: Path) -> list[str]:
    """The documented exception type, with a one-line message holding the key word."""
    try:
        case.call(folder)
    except Exception as exc:  # noqa: BLE001 - every exception is an outcome to grade here
        text = str(exc)
        problems = []
        if not isinstance(exc, case.expect):
            problems.append(f"{type(exc).__name__} raised, expected {case.expect.__name__}")
        if len(text.strip().splitlines()) != 1:
            problems.append("message is not one line")
        if case.match.lower() not in text.lower():
            problems.append(f"message lacks {case.match!r}: {text.strip()[:300]!r}")
        return problems
    return ["no exception"]


def case_problems(case: Case, folder: Path) -> list[str]:
    """Run ``case`` in the fresh ``folder``; what is wrong with its outcome (none: it behaves)."""
    folder.mkdir(parents=True, exist_ok=True)
    out = materialise(case, folder)
    if case.argv:
        argv = [a.replace("{d}", str(folder)).replace("{out}", str(out)) for a in case.argv]
        problems = cli_problems(case, *run_cli(argv))
    else:
        problems = call_problems(case, folder)
    if case.out is not None:
        problems += untouched(out, case.out)
    return problems


# The cases


def test_cases_cover_every_entry_point():
    """At least 40 cases, ids unique, each entry point with several, every command."""
    assert len(CASES) >= 40
    assert len({c.id for c in CASES}) == len(CASES)
    counts = {e: sum(c.entry == e for c in CASES) for e in ENTRY_POINTS}
    assert all(n >= 5 for n in counts.values()), counts
    commands = {c.argv[0] if c.argv[0] != "rig" else f"rig {c.argv[1]}" for c in CASES if c.argv}
    assert {"run", "scene", "compare", "sweep", "tolerance", "reproduce", "bench", "stress", "calibrate",
            "rig inspect", "rig measure", "rig validate", "rig synthetic"} <= commands


@pytest.mark.parametrize("case", CASES, ids=[c.id for c in CASES])
def test_bad_input(case, tmp_path):
    """Exit 2 with one line naming the problem (or the documented exception), no traceback, the
    given output untouched; a failed run exits 3 with its status and no non-finite number."""
    problems = case_problems(case, tmp_path / case.id)
    assert not problems, f"{case.id} ({case.entry}: {case.description}; {case.input}): " + "; ".join(problems)


def test_grading_flags_misbehaviour(tmp_path):
    """The grading itself: a case whose expectation is not met is reported with the reason."""
    expects_3 = Case("expects-3", "cli", "a bad option expected to fail as a run", ("run", "--angle", "x"),
                     expect=3, match="anything")
    touches = Case("touches-output", "cli", "a run that writes the output it was given",
                   ("run", "--name", "rig-literal-frictionless", "--engine", "reference", "--revolutions",
                    "1",
                    "--out", "{out}"), out="folder", expect=0)
    assert "exit status 2, expected 3" in case_problems(expects_3, tmp_path / "a")
    problems = case_problems(touches, tmp_path / "b")
    assert any("output folder changed" in p for p in problems), problems
    no_raise = Case("no-raise", "python api", "a call that succeeds", call=lambda d: None, expect=ValueError)
    assert case_problems(no_raise, tmp_path / "c") == ["no exception"]


# Atomic outputs


def _previous(folder: Path) -> None:
    folder.mkdir(parents=True)
    (folder / "marker.txt").write_text(MARKER)


def _intact(folder: Path) -> None:
    """Only the previous output in ``folder``, no temporary sibling left next to it."""
    assert sorted(p.name for p in folder.iterdir()) == ["marker.txt"]
    assert (folder / "marker.txt").read_text() == MARKER
    assert [p.name for p in folder.parent.iterdir() if p.name.startswith(f".{folder.name}")] == []


RUN = ["run", "--name", "rig-literal-frictionless", "--engine", "reference", "--revolutions", "1"]


@pytest.mark.parametrize("stop", [KeyboardInterrupt, RuntimeError])
def test_run_out_interrupted_keeps_previous(tmp_path, monkeypatch, stop):
    """`cardan run --out`: stopped after timeseries.csv is written, before summary.json."""
    out = tmp_path / "run"
    _previous(out)
    real = cio.write_result_files

    def half(result, folder):
        result.table.to_csv(folder / "timeseries.csv", index=False)
        raise stop("stopped half-way")

    monkeypatch.setattr(cio, "write_result_files", half)
    if stop is KeyboardInterrupt:
        assert main([*RUN, "--out", str(out)]) == 130
    else:
        with pytest.raises(RuntimeError):
            main([*RUN, "--out", str(out)])
    _intact(out)
    monkeypatch.setattr(cio, "write_result_files", real)
    assert main([*RUN, "--out", str(out)]) == 0  # and the next run replaces it whole
    assert sorted(p.name for p in out.iterdir()) == ["summary.json", "timeseries.csv"]


def test_compare_out_interrupted_keeps_previous(tmp_path, monkeypatch):
    """`cardan compare --out`: interrupted while drawing the plots, after the tables."""
    import cardan_exudyn.studies.compare.report as compare

    out = tmp_path / "cmp"
    _previous(out)

    def plots(comparison, folder):
        (folder / "overlay_kinematics.png").write_bytes(b"half a png")
        raise KeyboardInterrupt

    monkeypatch.setattr(compare, "overlay_plots", plots)
    status = main(["compare", "--name", "rig-literal-frictionless", "--engines", "reference,exudyn",
                   "--revolutions", "1", "--out", str(out)])
    assert status == 130
    _intact(out)


def test_tolerance_out_failure_keeps_previous_study(tmp_path, monkeypatch):
    """`cardan tolerance montecarlo`: the report fails after the samples table is written; the
    previous study folder stays, the sweep records (resumable by design) are kept."""
    import cardan_exudyn.studies.tolerance.report as tolerance

    out = tmp_path / "mc"
    _previous(out / "study")
    def plots(*args):
        raise KeyboardInterrupt

    monkeypatch.setattr(tolerance, "monte_carlo_plots", plots)
    status = main(["tolerance", "montecarlo", "--name", "rig-matched", "--engine", "reference",
                   "--revolutions", "1", "--samples", "3", "--workers", "1", "--out", str(out)])
    assert status == 130
    _intact(out / "study")
    assert (out / "cases" / "cases.jsonl").is_file()


def test_atomic_write_leaves_no_temporary_file(tmp_path):
    """A writer that fails half-way leaves the previous file and no temporary file."""
    path = tmp_path / "a.json"
    path.write_text("previous")

    def half(f):
        f.write(b"{\"half\": ")
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        cio.atomic_write(path, half)
    assert path.read_text() == "previous"
    assert [p.name for p in tmp_path.iterdir()] == ["a.json"]


def test_atomic_directory_restores_previous_when_the_swap_fails(tmp_path, monkeypatch):
    """If the new folder cannot be renamed into place, the previous one is put back."""
    out = tmp_path / "out"
    _previous(out)
    real = os.replace
    calls = []

    def replace(src, dst):
        calls.append((src, dst))
        if len(calls) == 2:  # the new folder onto the target
            raise OSError("disk gone")
        return real(src, dst)

    monkeypatch.setattr(cio.os, "replace", replace)
    monkeypatch.setattr(cio, "exchange", lambda a, b: False)  # the two-rename fallback
    with pytest.raises(OSError), cio.atomic_directory(out) as tmp:
        (tmp / "new.txt").write_text("new")
    monkeypatch.setattr(cio.os, "replace", real)
    _intact(out)


def test_atomic_directory_never_replaces_a_file(tmp_path):
    """A file where the output folder should be is refused before anything is written."""
    out = tmp_path / "out"
    out.write_text(MARKER)
    with pytest.raises(cio.OutputError, match="not a folder"), cio.atomic_directory(out):
        pytest.fail("the block must not run")
    assert out.read_text() == MARKER
    assert [p.name for p in tmp_path.iterdir()] == ["out"]


# No NaN as a result

_NUMBER_NAN = re.compile(r"(?<![\w.])[-+]?(nan|inf)\b", re.IGNORECASE)


def _no_efficiency_printed(text: str) -> None:
    assert "mean efficiency" not in text
    assert not _NUMBER_NAN.search(re.sub(r"loop gain[^\n]*", "", text)), text


def _nan_engine(status: str, **summary):
    def run(scene, options=None):
        return Result(None, Summary.from_dict({"status": status, "reason": "forced" if status != "ok" else "",
                             "engine": "fake", "engine_version": "0", "scene": {"name": scene.name},
                             "mean_efficiency": math.nan, "mean_instantaneous_efficiency": math.inf,
                             "work_ratio": math.nan, "input_work": 0.0, "revolutions": 1,
                             "wall_time_s": 0.0, **summary}))
    return run


def test_forced_failure_prints_status_not_nan(tmp_path, monkeypatch, capsys):
    """An engine that fails with NaN/inf means: exit 3, the status line, no number; --json and
    summary.json carry null."""
    import cardan_exudyn.engines as engines

    real = engines.get_engine
    monkeypatch.setitem(engines.ENGINES, "fake", engines.Engine(
        "fake", "reference.engine.solve", "reference.engine.options:ReferenceOptions", "test double"))
    monkeypatch.setattr(engines, "get_engine",
                        lambda name: _nan_engine("integration_failure") if name == "fake" else real(name))
    assert main(["run", "--engine", "fake", "--out", str(tmp_path / "r")]) == 3
    out, err = capsys.readouterr()
    _no_efficiency_printed(out + err)
    assert "status: integration_failure: forced" in err
    summary = json.loads((tmp_path / "r" / "summary.json").read_text(), parse_constant=pytest.fail)
    assert summary["mean_efficiency"] is None
    assert main(["run", "--engine", "fake", "--json"]) == 3
    out, err = capsys.readouterr()
    summary = json.loads(out, parse_constant=pytest.fail)  # strict JSON: no NaN
    assert summary["mean_efficiency"] is None and summary["mean_instantaneous_efficiency"] is None


def test_zero_input_work_prints_undefined(monkeypatch, capsys):
    """A run that is ok but has no input work (0/0) says the efficiency is undefined."""
    import cardan_exudyn.engines as engines

    real = engines.get_engine
    monkeypatch.setitem(engines.ENGINES, "fake", engines.Engine(
        "fake", "reference.engine.solve", "reference.engine.options:ReferenceOptions", "test double"))
    monkeypatch.setattr(engines, "get_engine",
                        lambda name: _nan_engine("ok") if name == "fake" else real(name))
    assert main(["run", "--engine", "fake"]) == 0
    out, err = capsys.readouterr()
    assert "mean efficiency undefined (input work 0 J)" in out
    assert not _NUMBER_NAN.search(out + err)


def test_absurd_friction_self_locks_exit_3(capsys):
    """A real failure: friction coefficient 1e6 self-locks Exudyn's run at its start."""
    status = main(["run", "--name", "paper-literal", "--friction-spider", "1e6", "--revolutions", "1"])
    out, err = capsys.readouterr()
    assert status == 3
    assert "status: self_locking" in err
    _no_efficiency_printed(out + err)


def test_compare_with_failed_engines_prints_no_number(capsys):
    """`cardan compare` where both engines lock: statuses in the table, '-' for the numbers."""
    status = main(["compare", "--name", "paper-literal-50deg", "--engines", "reference,exudyn",
                   "--revolutions", "1"])
    out, err = capsys.readouterr()
    assert status == 3
    for engine in ("reference", "exudyn"):
        row = next(line for line in out.splitlines() if line.startswith(f"| {engine}"))
        assert row.split("|")[2].strip().startswith("self_locking"), row  # status column
        assert row.split("|")[3].strip() == "-", row  # mean efficiency column
    assert not _NUMBER_NAN.search(re.sub(r"loop gain[^|]*", "", out))


def test_calibrate_failed_case_prints_status(monkeypatch, capsys):
    """`cardan calibrate`: a held-out case whose run failed shows its status, exit 3."""
    import cardan_exudyn.studies.calibrate.command as calibrate

    rows = [{"case": "table2:0:2000", "used_in_fit": True, "paper": 0.99, "model": 0.98,
             "difference": -0.01, "status": "ok", "reason": ""},
            {"case": "table2:45:2000", "used_in_fit": False, "paper": 0.9, "model": math.nan,
             "difference": math.nan, "status": "self_locking", "reason": "loop gain >= 1"}]
    result = {"set": "matched", "engine": "reference", "fit_cases": ["table2:0:2000"], "method": "-",
              "parameters": {"spider_lever": 0.06}, "values": {"spider_lever": 0.06},
              "combinations": [], "rows": rows, "fit_rms": 0.01, "fit_max_abs": 0.01,
              "held_out_rms": math.nan, "held_out_max_abs": math.nan, "runs": 3, "wall_time_s": 1.0}
    monkeypatch.setattr(calibrate, "calibrate", lambda *a, **k: result)
    assert main(["calibrate"]) == 3
    out, err = capsys.readouterr()
    assert "| table2:45:2000 | no | 0.900 | self_locking | - |" in out
    assert "status: table2:45:2000: self_locking" in err
    _no_efficiency_printed(out.replace("mean efficiency", ""))


def test_reference_zero_input_work_finishes():
    """No load, no friction, no gravity: the input work cancels to ~0; the quadrature used to
    split its panels 40 times (2^40 panels: out of memory). Now it closes at once, and the
    efficiency of a joint that transmits and loses nothing is undefined (it was 1, issue 18)."""
    from reference.paper.scenes import named_scene
    from reference.scene.mapping import replace

    for angle in (0.0, 10.0):
        scene = replace(named_scene("paper-literal-frictionless"), revolutions=1, gravity=[0.0, 0.0, 0.0],
                        **{"load.torque": 0.0, "joint.geometry.shaft_angle_deg": angle})
        s = run(scene, "reference").summary
        assert s.status == Status.OK and s.mean_efficiency is None and s.power_flow == "none"
        assert any("efficiency is undefined" in w for w in s.warnings), s.warnings
        assert s.extras["quadrature"]["evaluations"] < 5000


def test_scene_file_switches_drive_kind(tmp_path):
    """A scene file on a speed-driven base may give an angle drive (it replaces the base's)."""
    from reference.scene.files import load_scene

    path = tmp_path / "s.toml"
    path.write_text('base = "paper-literal-frictionless"\n[drive]\nkind = "angle"\n'
                    "time = [0.0, 0.1, 0.2, 0.3]\nangle = [0.0, 7.0, 14.0, 21.0]\n")
    scene = load_scene(path)
    assert scene.drive.kind == "angle" and scene.drive.angle[-1] == 21.0
