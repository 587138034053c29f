"""The examples of README.md and docs/*.md run, so that they cannot go stale.

- Every ```python block is executed in a fresh temporary folder. A block that defines top-level
  ``test_*`` functions is a user's test file: pytest runs it (in this process, with ``pytester``;
  the installed plugin provides its fixtures).
- Every ```toml block that describes a scene loads with :func:`reference.load_scene` from a
  temporary file. Sweep specifications (they name a ``scene``, a ``grid``, ...) and project
  configuration (``[tool...]``) are only parsed as TOML: their own documents' tests run them.
- Every ``cardan ...`` command of a ```bash (or unlabelled) block parses with the CLI's parser;
  the quick ones listed in :data:`RUN` also run, in a temporary folder.

Conventions in the documents:

- A ```toml block whose first line is a comment naming a file (``# my_joint.toml: ...``, or a
  relative path such as ``# tests/data/joint.toml``) is written under that name into the folder
  where the same document's python blocks and commands run, so an example can load the scene
  shown above it.
- Before a python block runs, the commands of :data:`RUN` shown above it in the same document
  that write files (``--out``) run in its folder, as a reader would have run them: an example
  may read the file a command above it wrote.
- A block that must not run starts with the line ``# not run by tests/test_docs.py: <reason>``;
  the reason is required and shows in the test report as the skip reason.

Test ids are ``file:line`` of the block's opening fence (or of the command's line).
"""

from __future__ import annotations

import ast
import re
import shlex
from dataclasses import dataclass
from pathlib import Path

import pytest

from cardan_exudyn import cli
from reference import load_scene

pytest_plugins = ["pytester"]

# pytester forgets the modules imported while it is in use (the inner runs' too), and numpy's C
# extensions cannot be imported twice in a process: what the engines import on first use is
# imported here, before any pytester exists
import scipy.integrate  # noqa: E402, F401
import scipy.optimize  # noqa: E402, F401

import cardan_exudyn.testing.assertions  # noqa: E402, F401
from cardan_exudyn.engines import get_engine  # noqa: E402

get_engine("exudyn"), get_engine("reference")

try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10
    import tomli as tomllib

ROOT = Path(__file__).resolve().parent.parent
DOCUMENTS = (ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md")))
FENCE = re.compile(r"^(?P<indent>\s*)```(?P<info>[^`]*)$")
SKIP = re.compile(r"^#\s*not run by tests/test_docs\.py\s*:?\s*(?P<reason>.*)$")
NAMED_FILE = re.compile(r"^#\s*(?P<name>\w[\w/-]*(?:\.[\w-]+)*\.toml)\b")  # relative, no ".."
SHELL = ("", "bash", "sh", "shell", "console")
SWEEP_KEYS = {"scene", "grid", "random", "cases", "fixed"}
CONFIG_KEYS = {"tool", "project", "build-system"}
SEPARATORS = {"&&", "||", ";", "|"}
REDIRECTIONS = re.compile(r"^\d*(>>?|<)")

RUN = (
    "cardan run --angle 15 --revolutions 1 --json",
    "cardan run --scene my_joint.toml",
    "cardan run --scene my_joint.toml --engine reference --out out/my_joint",
    "cardan scene --name paper-10deg",
    "cardan rig synthetic --format lvm --out rig.lvm",
)
"""Commands (as written in the documents, comments left out) that run, not only parse: each
takes a few seconds at most. Every other command only parses: they take up to minutes."""


@dataclass(frozen=True)
class Block:
    """One fenced code block of a document."""

    path: Path
    line: int  # 1-based line of the opening fence
    language: str
    text: str

    @property
    def id(self) -> str:
        return f"{self.path.relative_to(ROOT)}:{self.line}"

    @property
    def skip_reason(self) -> str | None:
        """The reason given on a ``# not run by tests/test_docs.py: ...`` first line, else None."""
        first = self.text.lstrip("\n").split("\n", 1)[0]
        match = SKIP.match(first.strip())
        return None if match is None else match["reason"].strip()


@dataclass(frozen=True)
class Command:
    """One ``cardan`` command line of a shell block."""

    block: Block
    line: int
    argv: tuple[str, ...]

    @property
    def id(self) -> str:
        return f"{self.block.path.relative_to(ROOT)}:{self.line}"

    @property
    def text(self) -> str:
        return " ".join(("cardan", *self.argv))


def read_blocks(path: Path) -> list[Block]:
    """The fenced code blocks of a markdown file, their indentation removed."""
    blocks, opening, body = [], None, []
    for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), start=1):
        match = FENCE.match(line)
        if opening is None and match:
            opening, body = (number, match["indent"], match["info"].strip().split(" ")[0]), []
        elif opening is not None and match and not match["info"].strip():
            start, indent, language = opening
            text = "\n".join(b[len(indent):] if b.startswith(indent) else b for b in body)
            blocks.append(Block(path, start, language.lower(), text + "\n"))
            opening = None
        elif opening is not None:
            body.append(line)
    assert opening is None, f"{path.name}:{opening[0]}: code block never closed"
    return blocks


def logical_lines(block: Block) -> list[tuple[int, str]]:
    """Shell lines with their document line numbers, backslash continuations joined."""
    out, pending, start = [], "", None
    for offset, line in enumerate(block.text.splitlines(), start=1):
        start = block.line + offset if start is None else start
        if line.rstrip().endswith("\\"):
            pending += line.rstrip()[:-1] + " "
            continue
        out.append((start, pending + line))
        pending, start = "", None
    return out


def commands_of(block: Block) -> list[Command]:
    """The ``cardan`` commands of a shell block (also after ``&&``, before a redirection)."""
    out = []
    for line, text in logical_lines(block):
        words = shlex.split(text.strip().removeprefix("$ "), comments=True)
        segment: list[str] = []
        for word in [*words, "&&"]:
            if word not in SEPARATORS:
                segment.append(word)
                continue
            if segment and Path(segment[0]).name == "cardan":
                argv = segment[1:]
                cut = next((i for i, w in enumerate(argv) if REDIRECTIONS.match(w)), len(argv))
                out.append(Command(block, line, tuple(argv[:cut])))
            segment = []
    return out


BLOCKS = [b for path in DOCUMENTS for b in read_blocks(path)]
PYTHON = [b for b in BLOCKS if b.language == "python"]
TOML = [b for b in BLOCKS if b.language == "toml"]
COMMANDS = [c for b in BLOCKS if b.language in SHELL for c in commands_of(b)]


def named_files(path: Path) -> dict[str, str]:
    """The TOML blocks of a document that name their file on their first line."""
    files: dict[str, str] = {}
    for block in TOML:
        match = NAMED_FILE.match(block.text.lstrip("\n"))
        if block.path == path and match:
            assert match["name"] not in files, f"{block.id}: a second block named {match['name']}"
            files[match["name"]] = block.text
    return files


@pytest.fixture
def folder(tmp_path: Path, monkeypatch: pytest.MonkeyPatch):
    """A temporary working folder; ``prepare(document)`` enters it (or the folder ``where``) and
    writes the document's named files into it."""

    def prepare(document: Path, where: Path = tmp_path) -> Path:
        monkeypatch.chdir(where)
        for name, text in named_files(document).items():
            (where / name).parent.mkdir(parents=True, exist_ok=True)
            (where / name).write_text(text, encoding="utf-8")
        return where

    return prepare


def skip_if_marked(block: Block) -> None:
    """Skip the test of a block marked ``# not run by tests/test_docs.py: <reason>``."""
    reason = block.skip_reason
    if reason is not None:
        assert reason, f"{block.id}: say why the block must not run"
        pytest.skip(reason)


def defines_tests(block: Block) -> bool:
    """Whether a python block is a test file (it defines top-level ``test*`` functions)."""
    tree = ast.parse(block.text, filename=block.id)
    return any(isinstance(node, ast.FunctionDef) and node.name.startswith("test")
               for node in tree.body)


def run_as_test_file(block: Block, pytester: pytest.Pytester) -> None:
    """Run a block that defines test functions as a user's test file, with pytest.

    In this process (``pytester``): a subprocess would import the engines again for every block.
    The hypothesis plugin is left out of the inner run: it does not survive being loaded twice.
    """
    pytester.makepyfile(**{f"test_docs_example_{block.line}": block.text})
    result = pytester.runpytest("-p", "no:cacheprovider", "-p", "no:hypothesispytest")
    assert result.ret == 0, f"{block.id} as a test file:\n{result.stdout.str()}"


def run_command(command: Command) -> None:
    """Run a documented command in this process, in the current folder; it must succeed."""
    status = cli.main(list(command.argv))
    assert status == 0, f"{command.id}: `{command.text}` exited with status {status}"


def writers_above(block: Block) -> list[Command]:
    """The quick commands above ``block`` in its document that write files."""
    return [c for c in COMMANDS if c.block.path == block.path and c.line < block.line
            and c.text in RUN and "--out" in c.argv]


@pytest.mark.parametrize("block", PYTHON, ids=[b.id for b in PYTHON])
def test_python_example_runs(block: Block, folder, request: pytest.FixtureRequest,
                             capsys: pytest.CaptureFixture) -> None:
    skip_if_marked(block)
    pytester = request.getfixturevalue("pytester") if defines_tests(block) else None
    folder(block.path, *([pytester.path] if pytester is not None else []))
    for command in writers_above(block):
        run_command(command)
    capsys.readouterr()  # the commands' output is not the example's
    if pytester is not None:
        run_as_test_file(block, pytester)
        return
    code = compile(block.text, block.id, "exec")
    exec(code, {"__name__": "__docs_example__"})


def toml_kind(data: dict) -> str:
    """What a TOML block is: a scene unless it has a sweep's or a project file's keys (so a
    mistyped scene key still makes the block a scene, which then fails to load)."""
    if CONFIG_KEYS & set(data):
        return "configuration"
    if SWEEP_KEYS & set(data):
        return "sweep specification"
    return "scene"


@pytest.mark.parametrize("block", TOML, ids=[b.id for b in TOML])
def test_toml_scene_loads(block: Block, folder) -> None:
    skip_if_marked(block)
    data = tomllib.loads(block.text)
    if toml_kind(data) != "scene":
        return  # valid TOML; what it configures is run by its own document's tests
    where = folder(block.path)
    scene_file = where / "docs_example_scene.toml"
    scene_file.write_text(block.text, encoding="utf-8")
    load_scene(scene_file)


@pytest.mark.parametrize("command", COMMANDS, ids=[c.id for c in COMMANDS])
def test_command_parses(command: Command, capsys: pytest.CaptureFixture) -> None:
    skip_if_marked(command.block)
    try:
        cli.build_parser().parse_args(list(command.argv))
    except SystemExit as exc:
        assert exc.code == 0, f"{command.id}: `{command.text}` does not parse: {capsys.readouterr().err}"


QUICK = [c for c in COMMANDS if c.text in RUN]


@pytest.mark.parametrize("command", QUICK, ids=[c.id for c in QUICK])
def test_quick_command_runs(command: Command, folder) -> None:
    skip_if_marked(command.block)
    folder(command.block.path)
    run_command(command)


def test_every_quick_command_is_in_a_document() -> None:
    """A command of :data:`RUN` that the documents no longer show would silently stop running."""
    shown = {c.text for c in COMMANDS}
    assert [c for c in RUN if c not in shown] == []


LINK = re.compile(r"\]\((?P<target>[^)#\s]+)(?:#[^)]*)?\)")


@pytest.mark.parametrize("path", DOCUMENTS, ids=[p.name for p in DOCUMENTS])
def test_relative_links_resolve(path: Path) -> None:
    text = path.read_text(encoding="utf-8")
    targets = {m["target"] for m in LINK.finditer(text) if "://" not in m["target"]}
    missing = sorted(t for t in targets if not (path.parent / t).exists())
    assert missing == [], f"{path.relative_to(ROOT)} links to missing files"
