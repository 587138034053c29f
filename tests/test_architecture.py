"""The shape of the house: import direction and cycles, one engine dispatch, sizes, public faces.

Figures behind these tests: ``python tests/code_metrics.py``.
"""

from __future__ import annotations

import ast
import importlib
import re
from pathlib import Path

import pytest
from code_metrics import (
    PACKAGES,
    ROOT,
    cycles,
    functions,
    import_graph,
    module_lines,
    module_name,
    product_files,
)

FORBIDDEN = {
    "reference": {"exudyn", "cardan_exudyn", "rigdata"},
    "cardan_exudyn": {"rigdata"},
}
MAX_MODULE_LINES = 600
MAX_FUNCTION_LINES = 60
# modules that may print: the command line and the study commands (their computations return
# data, their reports write files)
MAY_PRINT = re.compile(r"^(cardan_exudyn\.cli|cardan_exudyn\.studies\.\w+\.command|rigdata\.cli"
                       r"|rigdata\.campaign\.command|rigdata\.synthetic\.command)$")
ENGINE_RUN_MODULES = {"cardan_exudyn.model.accuracy", "reference.engine.solve", "cardan_exudyn.mujoco.engine"}


def imported_roots(path: Path) -> set[str]:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    roots = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            roots |= {a.name.split(".")[0] for a in node.names}
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            roots.add(node.module.split(".")[0])
    return roots


@pytest.fixture(scope="module")
def graph() -> dict[str, set[str]]:
    return import_graph()


@pytest.mark.parametrize("package", sorted(FORBIDDEN))
def test_import_direction(package):
    """No module of a package imports a package above it: reference <- cardan_exudyn <- rigdata."""
    offenders = {str(p.relative_to(ROOT)): imported_roots(p) & FORBIDDEN[package]
                 for p in (ROOT / package).rglob("*.py")}
    assert not {k: v for k, v in offenders.items() if v}


def test_no_import_cycles(graph):
    """No two product modules import each other, directly or through others, function-level
    imports included."""
    assert cycles(graph) == []


def test_only_the_cli_imports_studies(graph):
    """Inside cardan_exudyn nothing imports the studies or the CLI except the CLI (and studies
    each other); rigdata registers its command through an entry point."""
    def is_job(m: str) -> bool:
        return m == "cardan_exudyn.cli" or m.startswith("cardan_exudyn.studies")

    offenders = {m: sorted(filter(is_job, deps)) for m, deps in graph.items()
                 if not is_job(m) and any(map(is_job, deps))}
    assert offenders == {}


def test_the_product_never_imports_the_benchmarks():
    """``tests/benchmarks`` (the research tooling, not installed) is imported by no product module."""
    offenders = {str(p.relative_to(ROOT)) for pkg in PACKAGES for p in (ROOT / pkg).rglob("*.py")
                 if "benchmarks" in imported_roots(p)}
    assert offenders == set()


def test_metrics_see_a_cycle(tmp_path):
    """The cycle finder finds a function-level import cycle (so the test above can fail)."""
    pkg = tmp_path / "reference"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "a.py").write_text("def f():\n    from reference import b\n")
    (pkg / "b.py").write_text("import reference.a\n")
    for name in ("cardan_exudyn", "rigdata"):
        (tmp_path / name).mkdir()
    assert cycles(import_graph(tmp_path)) == [["reference.a", "reference.b"]]


def _product_sources() -> list[tuple[str, str]]:
    return [(module_name(p), p.read_text(encoding="utf-8")) for p in product_files()]


def test_engine_runs_go_through_the_dispatch():
    """No engine-string dispatch and no engine's run function imported outside engines.py; the
    reference package, which cannot import cardan_exudyn, may run its own engine (the paper's
    data solve a load with it: reference.paper.loads.solve_mean_input_load)."""
    dispatch = re.compile(r"""(==|!=)\s*["'](exudyn|reference|mujoco)["']|"""
                          r"""in\s*\(\s*["'](exudyn|reference|mujoco)["']""")
    offenders = []
    for module, text in _product_sources():
        if module == "cardan_exudyn.engines":
            continue
        offenders += [f"{module}: {m.group(0)}" for m in dispatch.finditer(text)]
        for node in ast.walk(ast.parse(text)):
            if isinstance(node, ast.ImportFrom) and node.module in ENGINE_RUN_MODULES \
                    and not (module.startswith("reference.") and node.module == "reference.engine.solve"):
                offenders += [f"{module}: from {node.module} import run"
                              for a in node.names if a.name == "run"]
    assert offenders == []


def test_tests_run_engines_through_the_dispatch():
    """Tests run engines as users do, through cardan_exudyn.run; only the reference package's own
    tests (test_reference_*.py) call its engine directly, as a user without Exudyn would."""
    offenders = []
    for path in sorted((ROOT / "tests").glob("test_*.py")):
        if path.name.startswith("test_reference_"):
            continue
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom) and node.module in ENGINE_RUN_MODULES:
                offenders += [f"{path.name}: from {node.module} import run"
                              for a in node.names if a.name == "run"]
    assert offenders == []


def test_module_sizes():
    """No product module over 600 lines."""
    assert {m: n for m, n in module_lines().items() if n > MAX_MODULE_LINES} == {}


def test_function_lengths():
    """No function body over 60 lines (docstring excluded)."""
    long = [f"{f.module}:{f.name} ({f.length} lines)" for p in product_files() for f in functions(p)
            if f.length > MAX_FUNCTION_LINES]
    assert long == []


def test_library_code_does_not_print():
    """Only the CLI and the study commands print; library code returns data."""
    offenders = []
    for module, text in _product_sources():
        if MAY_PRINT.match(module):
            continue
        for node in ast.walk(ast.parse(text)):
            if (isinstance(node, ast.Call) and isinstance(node.func, ast.Name)
                    and node.func.id == "print"):
                offenders.append(f"{module}:{node.lineno}")
    assert offenders == []


def test_no_private_names_imported_across_modules():
    """``from x import _name`` never reaches into another product module's private names."""
    offenders = []
    for module, text in _product_sources():
        for node in ast.walk(ast.parse(text)):
            if isinstance(node, ast.ImportFrom) and (node.module or "").split(".")[0] in PACKAGES:
                offenders += [f"{module}: {node.module}.{a.name}" for a in node.names
                              if a.name.startswith("_")]
    assert offenders == []


def test_broad_excepts_reraise_or_say_why():
    """``except Exception`` / ``except BaseException`` / bare ``except`` either re-raise (clean-up)
    or stand at a boundary that records the error, with a comment on the line saying so: a bug is
    never turned into a result silently."""
    offenders = []
    for module, text in _product_sources():
        lines = text.splitlines()
        for node in ast.walk(ast.parse(text)):
            if not isinstance(node, ast.ExceptHandler):
                continue
            broad = node.type is None or (isinstance(node.type, ast.Name)
                                          and node.type.id in ("Exception", "BaseException"))
            reraises = any(isinstance(n, ast.Raise) and n.exc is None for n in ast.walk(node))
            if broad and not reraises and "#" not in lines[node.lineno - 1]:
                offenders.append(f"{module}:{node.lineno}")
    assert offenders == []


def test_no_banner_comments():
    """Comments say why; no decorative banner lines."""
    banner = re.compile(r"^\s*#\s*[-=#*]{4,}", re.MULTILINE)
    offenders = [f"{m}: {b.group(0).strip()}" for m, text in _product_sources()
                 for b in banner.finditer(text)]
    assert offenders == []


def test_every_subpackage_names_its_face():
    """Every package of the product declares ``__all__`` (names or submodules) in its __init__."""
    missing = [str(p.relative_to(ROOT)) for pkg in PACKAGES for p in (ROOT / pkg).rglob("__init__.py")
               if "__all__" not in p.read_text(encoding="utf-8")]
    assert missing == []


@pytest.mark.parametrize("package", PACKAGES)
def test_public_face(package):
    """Each package names its public API in ``__all__``; every name resolves and ``dir`` shows it."""
    module = importlib.import_module(package)
    assert module.__all__, f"{package}.__all__ is empty"
    for name in module.__all__:
        assert getattr(module, name) is not None, name
    assert set(module.__all__) <= set(dir(module))
