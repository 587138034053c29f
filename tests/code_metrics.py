"""Static facts about the product code (``reference``, ``cardan_exudyn``, ``rigdata``): module
sizes, function lengths, the import graph. ``tests/test_architecture.py`` asserts on them; run
this file to print the figures::

    python tests/code_metrics.py [ROOT]

A function's length is its body without the docstring, in lines (``end_lineno`` of the last
statement minus the line of the first, plus one), nested functions counted in their parent too.
"""

from __future__ import annotations

import ast
import statistics
import sys
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("reference", "cardan_exudyn", "rigdata")


@dataclass(frozen=True)
class Function:
    module: str
    name: str
    line: int
    length: int


def module_name(path: Path, root: Path = ROOT) -> str:
    parts = list(path.relative_to(root).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def product_files(root: Path = ROOT) -> list[Path]:
    return sorted(p for pkg in PACKAGES for p in (root / pkg).rglob("*.py"))


def body_length(node: ast.FunctionDef | ast.AsyncFunctionDef) -> int:
    body = node.body
    if (len(body) > 1 and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant)
            and isinstance(body[0].value.value, str)):
        body = body[1:]
    return body[-1].end_lineno - body[0].lineno + 1


def functions(path: Path, root: Path = ROOT) -> Iterator[Function]:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            yield Function(module_name(path, root), node.name, node.lineno, body_length(node))


def module_lines(root: Path = ROOT) -> dict[str, int]:
    return {module_name(p, root): len(p.read_text(encoding="utf-8").splitlines())
            for p in product_files(root)}


def _resolve(module: str, name: str | None, known: set[str]) -> str | None:
    """The product module an import refers to (a submodule when ``name`` is one)."""
    if name is not None and f"{module}.{name}" in known:
        return f"{module}.{name}"
    return module if module in known else None


def imports(path: Path, root: Path = ROOT, known: set[str] | None = None) -> set[str]:
    """Product modules ``path`` imports anywhere (module level or inside functions).

    The parent packages an import also executes are not counted: a package face that imports
    its submodules is no cycle; a submodule importing names from its own package face is.
    """
    known = known if known is not None else {module_name(p, root) for p in product_files(root)}
    me = module_name(path, root)
    package = me if path.name == "__init__.py" else me.rpartition(".")[0]
    out: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        targets: list[str | None] = []
        if isinstance(node, ast.Import):
            targets = [_resolve(a.name, None, known) for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = package.rsplit(".", node.level - 1)[0] if node.level > 1 else package
                base = f"{anchor}.{base}" if base else anchor
            targets = [_resolve(base, a.name, known) for a in node.names]
        out |= set(filter(None, targets))
    out.discard(me)
    return out


def import_graph(root: Path = ROOT) -> dict[str, set[str]]:
    known = {module_name(p, root) for p in product_files(root)}
    return {module_name(p, root): imports(p, root, known) for p in product_files(root)}


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components with more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in graph.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return found


def docstring_lines(path: Path) -> tuple[int, int]:
    """(docstring lines, code lines) of a module: docstrings of the module, classes and functions
    (and attribute docstrings, string statements) against every other non-blank, non-comment line."""
    text = path.read_text(encoding="utf-8")
    doc_rows: set[int] = set()
    for node in ast.walk(ast.parse(text)):
        if (isinstance(node, ast.Expr) and isinstance(node.value, ast.Constant)
                and isinstance(node.value.value, str)):
            doc_rows.update(range(node.lineno, node.end_lineno + 1))
    code = 0
    for number, line in enumerate(text.splitlines(), start=1):
        stripped = line.strip()
        if stripped and not stripped.startswith("#") and number not in doc_rows:
            code += 1
    return len(doc_rows), code


def packed_assignments(path: Path) -> list[int]:
    """Lines assigning a literal tuple of two or more expressions to as many names
    (``a, b = f(x), g(y)``): statements packed onto one line."""
    found = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if (isinstance(node, ast.Assign) and len(node.targets) == 1
                and isinstance(node.targets[0], ast.Tuple) and isinstance(node.value, ast.Tuple)
                and len(node.value.elts) >= 2):
            found.append(node.lineno)
    return found


def figures(root: Path = ROOT) -> dict[str, float]:
    """The headline figures of the product code: modules, lines, docstring lines per 100 code
    lines, functions over 30 lines, packed tuple assignments."""
    files = product_files(root)
    docs = [docstring_lines(p) for p in files]
    lengths = [f.length for p in files for f in functions(p, root)]
    return {
        "modules": len(files),
        "lines": sum(module_lines(root).values()),
        "docstring_lines_per_100_code": round(100 * sum(d for d, _ in docs) / sum(c for _, c in docs), 1),
        "functions": len(lengths),
        "functions_over_30": sum(n > 30 for n in lengths),
        "packed_assignments": sum(len(packed_assignments(p)) for p in files),
    }


def report(root: Path = ROOT) -> str:
    sizes = module_lines(root)
    lengths = [f.length for p in product_files(root) for f in functions(p, root)]
    deciles = statistics.quantiles(lengths, n=10)
    over_60 = sorted((f for p in product_files(root) for f in functions(p, root) if f.length > 60),
                     key=lambda f: -f.length)
    headline = figures(root)
    lines = [
        "figures: " + ", ".join(f"{k} {v}" for k, v in headline.items()),
        f"modules: {len(sizes)}, lines: {sum(sizes.values())}, largest: "
        + ", ".join(f"{m} {n}" for m, n in sorted(sizes.items(), key=lambda kv: -kv[1])[:5]),
        f"modules over 600 lines: {sum(n > 600 for n in sizes.values())}",
        f"functions: {len(lengths)}, median length {statistics.median(lengths):g}, "
        f"90th percentile {deciles[-1]:g}, over 30 lines {sum(n > 30 for n in lengths)}, "
        f"over 60 lines {len(over_60)}",
        *(f"  {f.module}:{f.name} {f.length}" for f in over_60),
        f"import cycles: {cycles(import_graph(root)) or 'none'}",
    ]
    return "\n".join(lines)


def summary_line(path: Path) -> str:
    """The first line of a module's docstring ("" when it has none)."""
    doc = ast.get_docstring(ast.parse(path.read_text(encoding="utf-8"))) or ""
    return doc.strip().splitlines()[0] if doc.strip() else ""


def tree(root: Path = ROOT) -> str:
    """The installed packages as a tree: every package and module with its lines and the first
    line of its docstring."""
    out: list[str] = []
    for pkg in PACKAGES:
        for path in sorted((root / pkg).rglob("*.py"),
                           key=lambda p: (p.parent.relative_to(root).parts, p.name != "__init__.py", p.name)):
            rel = path.relative_to(root)
            depth = len(rel.parts) - 1
            if path.name == "__init__.py":
                label = f"{rel.parent.name}/"
                depth -= 1
            else:
                label = path.name
            lines = len(path.read_text(encoding="utf-8").splitlines())
            out.append(f"{'    ' * depth}{label:<{36 - 4 * depth}} {lines:>4}  {summary_line(path)[:90]}")
    return "\n".join(out)


def figures_at(revision: str, root: Path = ROOT) -> dict[str, float]:
    """:func:`figures` of the product code at a git ``revision`` (extracted to a temporary folder)."""
    import subprocess
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        archive = subprocess.run(["git", "-C", str(root), "archive", revision, *PACKAGES],
                                 capture_output=True, check=True).stdout
        subprocess.run(["tar", "-x", "-C", tmp], input=archive, check=True)
        return figures(Path(tmp))


def compare(revision: str, root: Path = ROOT) -> str:
    """The headline figures at ``revision`` and in the working tree, side by side."""
    before = figures_at(revision, root)
    after = figures(root)
    rows = [f"{'figure':<30} {revision[:12]:>12} {'now':>10}"]
    rows += [f"{k:<30} {before[k]:>12} {after[k]:>10}" for k in after]
    return "\n".join(rows)


USAGE = """usage: python tests/code_metrics.py [ROOT]      sizes, lengths, cycles of the product code
       python tests/code_metrics.py --tree        the packages' tree with lines and summaries
       python tests/code_metrics.py --since REV   headline figures at git REV and now"""


if __name__ == "__main__":
    args = sys.argv[1:]
    if args[:1] == ["--tree"]:
        print(tree())
    elif args[:1] == ["--since"] and len(args) == 2:
        print(compare(args[1]))
    elif args and args[0].startswith("-"):
        sys.exit(USAGE)
    else:
        print(report(Path(args[0]).resolve() if args else ROOT))
