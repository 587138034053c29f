"""The numbers README.md and docs/*.md print from a command, computed again and compared with the
printed digits, so that they cannot drift from what the code gives (tests/test_docs.py runs the
examples; this checks the numbers the text quotes).

Checked in the default suite (reference engine, exact to its quadrature's 1e-9, and one Exudyn
row; a few seconds):

- README's results table: the reference column of every row, and every column of the
  ``my_joint.toml`` row (value, true error, estimate); the quadrature's error estimates quoted
  above it;
- the printed lines quoted in README.md and docs/accuracy.md (``cardan run --name ...`` prints
  ``mean efficiency ...``), and the ``# mean efficiency X`` / ``# ok, X`` comments of the
  ``cardan run`` commands in README.md and docs/paper.md;
- README's time average of eq. (18) for ``paper-literal-35deg`` (-0.83 against 0.25);
- the parameter sets' numbers in README.md and docs/paper.md (``cardan calibrate``'s errors on the
  paper's eleven numbers under the stored sets, the envelope stored by ``cardan calibrate
  --envelope``, the conclusions table).

``-m slow``: the Exudyn columns of README's other rows and the sentence under the table that
sums them up (floors, true error against estimate, within the target).

Each printed number is compared as text, formatted as the document prints it; a mismatch lists
every number that drifted, printed against computed.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import pytest

import cardan_exudyn
from cardan_exudyn.cli import build_parser, main
from cardan_exudyn.model.accuracy import MODEL_FLOOR
from cardan_exudyn.scene_options import scene_from_args
from cardan_exudyn.studies.calibrate.fit import case_rows, fit_statistics
from cardan_exudyn.studies.calibrate.fitting import CaseModel
from cardan_exudyn.testing import make_scene
from reference.paper.cases import envelope, paper_cases
from reference.paper.parameter_sets import parameter_set, set_values

pytest_plugins = ["pytester"]

ROOT = Path(__file__).resolve().parent.parent
README = ROOT / "README.md"
PAPER = ROOT / "docs" / "paper.md"
ACCURACY = ROOT / "docs" / "accuracy.md"
ENGINES = ROOT / "docs" / "engines.md"
PYTEST = ROOT / "docs" / "pytest.md"
EXUDYN_CELL = re.compile(r"^(?P<value>[0-9.]+) \((?P<error>[+-][0-9.]+e[+-]\d+); "
                         r"est\. (?P<estimate>[0-9.]+e[+-]\d+)\)$")


def prose(path: Path) -> str:
    """A document's text with every run of whitespace one space (sentences wrap anywhere)."""
    return " ".join(path.read_text(encoding="utf-8").split())


def table_after(path: Path, header: str) -> list[list[str]]:
    """The cells of the markdown table whose header line starts with ``header``, header first."""
    lines = path.read_text(encoding="utf-8").splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith(header))
    rows = []
    for line in lines[start:]:
        if not line.startswith("|"):
            break
        if not set(line) <= set("|-: "):
            rows.append([c.strip() for c in line.strip().strip("|").split("|")])
    return rows


def named_block(path: Path, name: str) -> str:
    """The ```toml block of ``path`` whose first line names the file ``name``."""
    match = re.search(rf"```toml\n(# {re.escape(name)}\b.*?)```", path.read_text(encoding="utf-8"), re.S)
    assert match, f"{path.name}: no toml block named {name}"
    return match.group(1)


def check(problems: list[str]) -> None:
    assert not problems, "printed numbers that drifted (document: printed, computed):\n" + "\n".join(problems)


def compare(problems: list[str], where: str, printed: str, computed: str) -> None:
    """Note ``where`` in ``problems`` when the printed text is not the computed one."""
    if printed != computed:
        problems.append(f"{where}: {printed}, {computed}")


def like(printed: str, value: float) -> str:
    """``value`` with as many decimals as the number in ``printed``, the text around it kept."""
    number = re.search(r"-?\d+(?:\.(\d+))?", printed)
    decimals = len(number.group(1) or "")
    return printed[:number.start()] + f"{value:.{decimals}f}" + printed[number.end():]


# --------------------------------------------------------------------------- README's results table

RESULTS_HEADER = "| scene | reference |"


def results_table() -> tuple[list[str], list[list[str]]]:
    rows = table_after(README, RESULTS_HEADER)
    return rows[0], rows[1:]


def column_accuracies(header: list[str]) -> list[str]:
    """``--accuracy`` of each Exudyn column, as the header gives it."""
    return [re.search(r"`--accuracy (\S+)`", cell).group(1) for cell in header[2:]]


def row_argv(cell: str) -> list[str]:
    """``cardan run`` options of a row: ``--name NAME`` or ``--scene FILE`` (the README's file)."""
    name = re.match(r"`([^`]+)`", cell).group(1)
    return ["--scene", name] if name.endswith(".toml") else ["--name", name]


@pytest.fixture(scope="module")
def readme_folder(tmp_path_factory) -> Path:
    """A folder holding README's ``my_joint.toml``, where its commands run."""
    folder = tmp_path_factory.mktemp("readme")
    (folder / "my_joint.toml").write_text(named_block(README, "my_joint.toml"), encoding="utf-8")
    return folder


def cli_scene(folder: Path, argv: list[str]):
    """The scene ``cardan run ARGV`` runs (the command's own scene construction, in ``folder``)."""
    argv = [str(folder / a) if a.endswith(".toml") else a for a in argv]
    return scene_from_args(build_parser().parse_args(["run", *argv]))


@pytest.fixture(scope="module")
def references(readme_folder) -> dict[str, object]:
    """The reference engine's summary of every row of the table, by the row's first cell."""
    _, rows = results_table()
    return {row[0]: cardan_exudyn.run(cli_scene(readme_folder, row_argv(row[0])), "reference").summary
            for row in rows}


def exudyn_cells(folder: Path, row: list[str], accuracies: list[str], reference) -> list[dict]:
    """Exudyn's cells of a row, computed: the run at each accuracy, formatted as printed."""
    out = []
    for accuracy in accuracies:
        s = cardan_exudyn.run(cli_scene(folder, [*row_argv(row[0]), "--accuracy", accuracy])).summary
        error = s.mean_efficiency - reference.mean_efficiency
        out.append({"text": f"{s.mean_efficiency:.6f} ({error:+.1e}; est. {s.efficiency_error_estimate:.1e})",
                    "error": error, "estimate": s.efficiency_error_estimate, "accuracy": float(accuracy),
                    "floored": s.efficiency_error_estimate == MODEL_FLOOR * s.accuracy.model})
    return out


def test_readme_reference_column(references):
    """Every row's reference column is what the reference engine gives."""
    _, rows = results_table()
    problems: list[str] = []
    for row in rows:
        compare(problems, f"README {row[0]} reference", row[1], f"{references[row[0]].mean_efficiency:.6f}")
    check(problems)


def test_readme_quadrature_errors(references):
    """The quadrature's error estimates quoted above the table: their largest and the works."""
    match = re.search(r"error estimates of the input and lost work \(at most (?P<error>\S+) J on works of "
                      r"(?P<low>\d+)-(?P<high>\d+) J in these scenes\)", prose(README))
    assert match, "README: the quadrature's error estimates are no longer quoted as expected"
    estimates = [s.extras["quadrature"][f"{w}_work_error_estimate"] for s in references.values()
                 for w in ("input", "loss")]
    works = [s.input_work for s in references.values()]
    problems: list[str] = []
    compare(problems, "README quadrature error", match["error"], f"{max(estimates):.1e}")
    compare(problems, "README works", f"{match['low']}-{match['high']}", f"{min(works):.0f}-{max(works):.0f}")
    check(problems)


def test_readme_my_joint_row(readme_folder, references):
    """The ``my_joint.toml`` row's Exudyn columns (one cheap Exudyn row: about a second)."""
    header, rows = results_table()
    [row] = [r for r in rows if ".toml" in r[0]]
    cells = exudyn_cells(readme_folder, row, column_accuracies(header), references[row[0]])
    problems: list[str] = []
    for printed, cell in zip(row[2:], cells, strict=True):
        assert EXUDYN_CELL.match(printed), f"README {row[0]}: cell {printed!r} not as expected"
        compare(problems, f"README {row[0]} at {cell['accuracy']:g}", printed, cell["text"])
    check(problems)


@pytest.mark.slow
def test_readme_exudyn_columns_and_their_summary(readme_folder, references):
    """Every Exudyn cell of the table, and the sentence under it: how many estimates sit at the
    a-priori model's floor, the range of true error over estimate, within the target in every row."""
    header, rows = results_table()
    cells = []
    problems: list[str] = []
    for row in rows:
        computed = exudyn_cells(readme_folder, row, column_accuracies(header), references[row[0]])
        for printed, cell in zip(row[2:], computed, strict=True):
            compare(problems, f"README {row[0]} at {cell['accuracy']:g}", printed, cell["text"])
        cells += computed
    match = re.search(r"\((?P<floored>\d+) of the (?P<cells>\d+) estimates above sit at that floor\); the "
                      r"true error was (?P<low>\S+) to (?P<high>\S+) times the estimate here, and within the "
                      r"target in every row", prose(README))
    assert match, "README: the sentence under the results table is no longer as expected"
    ratios = [abs(c["error"]) / c["estimate"] for c in cells]
    compare(problems, "README estimates at the floor", f"{match['floored']} of {match['cells']}",
            f"{sum(c['floored'] for c in cells)} of {len(cells)}")
    compare(problems, "README true error / estimate", f"{match['low']} to {match['high']}",
            f"{min(ratios):.2g} to {max(ratios):.2g}")
    outside = [c["text"] for c in cells if abs(c["error"]) > c["accuracy"]]
    compare(problems, "README cells outside their target", "none", ", ".join(outside) or "none")
    check(problems)


# --------------------------------------------------------------------------- printed lines and comments

QUOTED_LINES = [
    (README, r"printed by `(?P<command>cardan run [^`]+)` as `(?P<printed>mean efficiency [^`]+)`"),
    (ACCURACY, r"`(?P<command>cardan run [^`]+)` prints `(?P<printed>mean efficiency [^`]+)`"),
]
COMMENTED = re.compile(r"^\s*(?P<command>cardan run [^#\n]*?)\s+#\s*(?:mean efficiency|ok,)\s*"
                       r"(?P<value>[0-9.]+)", re.M)


def printed_by(argv: list[str], folder: Path, capsys, monkeypatch) -> str:
    """What ``cardan ARGV`` prints on stdout, run in this process in ``folder``."""
    monkeypatch.chdir(folder)
    capsys.readouterr()
    main(argv)
    return capsys.readouterr().out


def test_quoted_printed_lines(readme_folder, capsys, monkeypatch):
    """``cardan run ...`` prints the line the documents quote (README.md, docs/accuracy.md)."""
    problems: list[str] = []
    for path, pattern in QUOTED_LINES:
        match = re.search(pattern, prose(path))
        assert match, f"{path.name}: the quoted line of `cardan run` is no longer as expected"
        out = printed_by(match["command"].split()[1:], readme_folder, capsys, monkeypatch)
        if match["printed"] not in out:
            problems.append(f"{path.name} `{match['command']}`: {match['printed']}, {out.strip()}")
    check(problems)


@pytest.mark.parametrize("path", [README, PAPER], ids=lambda p: p.name)
def test_commented_commands(path, readme_folder, capsys, monkeypatch):
    """A ``cardan run`` command commented with its mean efficiency prints that efficiency."""
    commands = list(COMMENTED.finditer(path.read_text(encoding="utf-8")))
    assert commands, f"{path.name}: no commented `cardan run` command left"
    problems: list[str] = []
    for match in commands:
        out = printed_by(match["command"].split()[1:], readme_folder, capsys, monkeypatch)
        value = re.search(r"mean efficiency (\S+)", out).group(1)
        compare(problems, f"{path.name} `{match['command']}`", match["value"], value)
    check(problems)


def test_readme_time_average_of_eq18(references):
    """README: eq. (18)'s time average against the mean efficiency of ``paper-literal-35deg``
    (the average from the warning that says why it is not reported)."""
    match = re.search(r"it would be (?P<average>-?[0-9.]+) against a `mean_efficiency` of (?P<eta>[0-9.]+) "
                      r"for `(?P<name>[^`]+)`", prose(README))
    assert match, "README: the time average of eq. (18) is no longer quoted as expected"
    s = references[f"`{match['name']}`"]
    [note] = [w for w in s.warnings if "eq. (18)" in w]
    average = float(re.search(r"eq\. \(18\), (\S+), is outside", note).group(1))
    problems: list[str] = []
    compare(problems, "README average of eq. (18)", match["average"], f"{average:.2f}")
    compare(problems, "README mean efficiency", match["eta"], f"{s.mean_efficiency:.2f}")
    check(problems)


# --------------------------------------------------------------------------- the parameter sets

@pytest.fixture(scope="module")
def set_rows() -> dict[str, list[dict]]:
    """``cardan calibrate``'s rows (reference engine) for the stored physical and matched sets."""
    return {name: case_rows(CaseModel(), set_values(name), parameter_set(name)["fit_cases"])
            for name in ("physical", "matched")}


def row_of(rows: list[dict], case: str) -> dict:
    return next(r for r in rows if r["case"] == case)


def test_readme_parameter_sets(set_rows, references):
    """README's list of the parameter sets: errors on the paper's numbers, the 10 deg values, the
    envelope's highest value at 500 and 1000 rpm."""
    text = prose(README)
    physical = fit_statistics(set_rows["physical"])
    matched = fit_statistics(set_rows["matched"])
    match = re.search(r"RMS error (?P<fit>\S+) on those, (?P<held>\S+) \(largest (?P<largest>\S+)\) on the "
                      r"five held out\. 10 deg, 2000 rpm: (?P<ten>\S+) \(paper", text)
    assert match, "README: the physical set's errors are no longer quoted as expected"
    problems: list[str] = []
    compare(problems, "README physical fitted RMS", match["fit"], f"{physical['fit_rms']:.4f}")
    compare(problems, "README physical held-out RMS", match["held"], f"{physical['held_out_rms']:.4f}")
    compare(problems, "README physical held-out largest", match["largest"],
            f"{physical['held_out_max_abs']:.4f}")
    compare(problems, "README physical 10 deg", match["ten"],
            f"{row_of(set_rows['physical'], 'table2:10:2000')['model']:.4f}")
    literal = re.search(r"gravity on the bearings\): (\S+) at 10 deg", text).group(1)
    compare(problems, "README literal 10 deg", literal,
            f"{references['`paper-literal-10deg`'].mean_efficiency:.4f}")
    match = re.search(r"offset\): RMS (?P<fit>\S+) fitted, (?P<held>\S+) held out, largest (?P<largest>\S+) "
                      r"\(35 deg\)", text)
    compare(problems, "README matched fitted RMS", match["fit"], f"{matched['fit_rms']:.4f}")
    compare(problems, "README matched held-out RMS", match["held"], f"{matched['held_out_rms']:.4f}")
    compare(problems, "README matched largest", match["largest"], f"{matched['held_out_max_abs']:.4f}")
    highest = max(r["highest"] for r in envelope() if r["case"] in ("speed:10:500", "speed:10:1000"))
    printed = re.search(r"gives at most (\S+) there", text).group(1)
    compare(problems, "README envelope", printed, f"{highest:.4f}")
    check(problems)


CASE_LABELS = {f"table2:{a}:2000": f"Table 2, {a} deg" for a in range(0, 40, 5)}
CASE_LABELS.update({f"speed:10:{rpm}": f"10 deg, {rpm} rpm" for rpm in (500, 1000, 2000)})


def test_paper_physical_set_table(set_rows):
    """docs/paper.md: the physical set's errors on the eleven numbers, and its summary line."""
    rows = set_rows["physical"]
    problems: list[str] = []
    printed = {r[0]: r for r in table_after(PAPER, "| case | used in fit | paper | physical |")[1:]}
    assert set(printed) == {CASE_LABELS[r["case"]] for r in rows} and len(rows) == len(paper_cases())
    for row in rows:
        computed = ["yes" if row["used_in_fit"] else "no", f"{row['paper']:.3f}", f"{row['model']:.4f}",
                    f"{row['difference']:+.4f}"]
        label = CASE_LABELS[row["case"]]
        compare(problems, f"paper.md {label}", " | ".join(printed[label][1:]), " | ".join(computed))
    stats = fit_statistics(rows)
    fitted = max((r for r in rows if r["used_in_fit"]), key=lambda r: abs(r["difference"]))
    held = max((r for r in rows if not r["used_in_fit"]), key=lambda r: abs(r["difference"]))
    line = re.search(r"Fitted: RMS (\S+), largest (\S+) \((\d+) rpm\); held out: RMS (\S+), largest (\S+) "
                     r"\((\d+) rpm\)\.", prose(PAPER))
    computed = (f"{stats['fit_rms']:.4f}", f"{stats['fit_max_abs']:.4f}", fitted["case"].split(":")[-1],
                f"{stats['held_out_rms']:.4f}", f"{stats['held_out_max_abs']:.4f}",
                held["case"].split(":")[-1])
    compare(problems, "paper.md physical summary", " ".join(line.groups()), " ".join(computed))
    check(problems)


def test_paper_matched_set_statistics(set_rows):
    """docs/paper.md: the matched set's errors under the reference engine (the command it gives)."""
    stats = fit_statistics(set_rows["matched"])
    worst = row_of(set_rows["matched"], "table2:35:2000")
    match = re.search(r"reference engine: fitted RMS (\S+), largest (\S+); \*\*held out RMS (\S+), "
                      r"largest (\S+)\*\* \(35 deg: (\S+) against (\S+)\)", prose(PAPER))
    computed = (f"{stats['fit_rms']:.4f}", f"{stats['fit_max_abs']:.4f}", f"{stats['held_out_rms']:.4f}",
                f"{stats['held_out_max_abs']:.4f}", f"{worst['model']:.4f}", f"{worst['paper']:.3f}")
    problems: list[str] = []
    compare(problems, "paper.md matched statistics", " ".join(match.groups()), " ".join(computed))
    check(problems)


def test_paper_envelope_table():
    """docs/paper.md: the envelope table is the stored ``[envelope]`` (lowest and highest)."""
    printed = {r[0]: r for r in table_after(PAPER, "| case | paper | lowest | highest |")[1:]}
    problems: list[str] = []
    for row in envelope():
        label = CASE_LABELS[row["case"]]
        # the stored values carry 6 decimals: a stored 0.69675 prints as 0.6967 or 0.6968
        for printed_value, stored in zip(printed[label][2:4], (row["lowest"], row["highest"]), strict=True):
            if abs(float(printed_value) - stored) > 0.5e-4 + 1e-12:
                problems.append(f"paper.md envelope {label}: {printed_value}, {stored:.6f}")
    check(problems)


def test_paper_conclusions_table():
    """docs/paper.md: the paper's conclusions under each set (reference engine, the command given)."""
    printed = {r[0]: r for r in table_after(PAPER, "| claim | paper | physical | literal | matched |")[1:]}
    problems: list[str] = []
    for k, name in enumerate(("physical", "literal", "matched")):
        eta = {n: cardan_exudyn.run(cli_scene(ROOT, ["--name", f"paper-{name}-{n}"]), "reference")
               .mean_efficiency
               for n in ("10deg-500rpm", "10deg-1000rpm", "10deg-2000rpm", "0deg-2000rpm", "35deg-2000rpm")}
        speed = " / ".join(f"{eta[n]:.4f}" for n in ("10deg-500rpm", "10deg-1000rpm", "10deg-2000rpm"))
        drop = 1.0 - eta["10deg-2000rpm"] / eta["10deg-500rpm"]
        angle = f"{eta['0deg-2000rpm']:.4f} / {eta['35deg-2000rpm']:.4f}"
        angle_drop = 1.0 - eta["35deg-2000rpm"] / eta["0deg-2000rpm"]
        for claim, computed in (("speed: 10 deg at 500 / 1000 / 2000 rpm", speed),
                                ("speed: relative drop 500 -> 2000 rpm", 100 * drop),
                                ("angle: 0 and 35 deg at 2000 rpm", angle),
                                ("angle: relative drop 0 -> 35 deg", 100 * angle_drop)):
            cell = printed[claim][2 + k]
            compare(problems, f"paper.md {claim} ({name})", cell,
                    computed if isinstance(computed, str) else like(cell, computed))
    check(problems)


# --------------------------------------------------------------------------- docs/pytest.md, docs/engines.md

def test_pytest_examples_reference_values():
    """docs/pytest.md: the reference engine's value each example quotes for its scene."""
    text = PYTEST.read_text(encoding="utf-8")
    quoted = list(re.finditer(r"(?:cardan_scene|make_scene)\((?P<args>[^)]*)\)(?:(?!```).)*?the reference "
                              r"engine's value(?: for this scene is|,) (?P<value>[0-9.]+)", text, re.S))
    assert len(quoted) == 2, "docs/pytest.md: the quoted reference values are no longer as expected"
    problems: list[str] = []
    for match in quoted:
        scene = eval(f"make_scene({match['args']})", {"make_scene": make_scene})  # the example's own call
        value = cardan_exudyn.run(scene, "reference").mean_efficiency
        compare(problems, f"pytest.md {match['args']}", match["value"], like(match["value"], value))
    check(problems)


@pytest.mark.slow
def test_pytest_runs_table(pytester):
    """docs/pytest.md: the engine runs of its examples as ``--cardan-runs`` lists them (every column
    but the wall time), from running the examples."""
    text = PYTEST.read_text(encoding="utf-8")
    for block in re.findall(r"```toml\n(.*?)```", text, re.S):
        name, _, body = block.partition("\n")
        path = pytester.path / name.removeprefix("# ")
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(body, encoding="utf-8")
    for k, block in enumerate(re.findall(r"```python\n(.*?)```", text, re.S)):
        if "def test_" in block:
            pytester.makepyfile(**{f"test_docs_{k}": block})
    result = pytester.runpytest_subprocess("-p", "no:cacheprovider", "-p", "no:hypothesispytest",
                                           "--cardan-runs")
    assert result.ret == 0, result.stdout.str()

    def rows(lines) -> list[str]:
        return [" | ".join(c.strip() for i, c in enumerate(line.strip("|").split("|")) if i != 6)
                for line in lines if line.startswith("| ") and not line.startswith("| scene")]

    printed = rows(re.search(r"engine runs -+\n(.*?)```", text, re.S).group(1).splitlines())
    problems: list[str] = []
    compare(problems, "pytest.md runs table", "\n".join(printed), "\n".join(rows(result.outlines)))
    check(problems)


@pytest.mark.slow
def test_engines_convergence_line():
    """docs/engines.md: Exudyn's mean-efficiency error at 100-800 steps per revolution (10 deg)."""
    match = re.search(r"`cardan run --name (?P<name>\S+) --dt DT`\) (?P<errors>(?:\S+, ){3}\S+) at "
                      r"(?P<steps>[\d /]+) steps per revolution \(reference (?P<reference>\S+)\)",
                      prose(ENGINES))
    assert match, "docs/engines.md: the convergence line is no longer as expected"
    scene = cli_scene(ROOT, ["--name", match["name"]])
    reference = cardan_exudyn.run(scene, "reference").mean_efficiency
    errors = []
    for steps in match["steps"].split(" / "):
        dt = 2.0 * math.pi / abs(scene.drive.speed) / int(steps)
        stepped = cli_scene(ROOT, ["--name", match["name"], "--dt", repr(dt)])
        errors.append(f"{cardan_exudyn.run(stepped, error_estimate=False).mean_efficiency - reference:+.1e}")
    problems: list[str] = []
    compare(problems, "engines.md reference", match["reference"], f"{reference:.6f}")
    compare(problems, "engines.md errors", match["errors"], ", ".join(errors))
    check(problems)
