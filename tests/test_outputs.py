"""Output folders that survive anything (issue 18): the atomic exchange and its fallback, the
leftovers of killed commands, one writer per output, a full disk, the umask, honest summaries,
and folders that must never be replaced. Processes are real where the behaviour is about
processes (kills, concurrent writers, file size limits)."""

from __future__ import annotations

import errno
import json
import os
import random
import resource
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from processes import start, wait_for

import cardan_exudyn.outputs as cio
from cardan_exudyn.cli import main
from cardan_exudyn.sweep import run_sweep

# the reference engine: a second of work, a 0.7 MB time table to write
QUICK = ["run", "--name", "paper-literal-35deg", "--engine", "reference", "--revolutions", "1"]
LONG = ["run", "--name", "paper-literal-35deg", "--engine", "reference", "--revolutions", "4"]




def snapshot(folder: Path) -> dict[str, bytes]:
    """Every file under ``folder`` by relative path, with its bytes."""
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def siblings(out: Path) -> list[str]:
    """Hidden entries next to ``out`` that belong to it (temporary folders, lock files)."""
    return sorted(p.name for p in out.parent.iterdir() if p.name.startswith(f".{out.name}."))


def dead_pid() -> int:
    """The id of a process that has ended."""
    proc = subprocess.Popen([sys.executable, "-c", "pass"])
    proc.wait()
    return proc.pid


def one_error_line(stderr: str, text: str) -> bool:
    """The command's stderr ends with one error line holding ``text``, and no traceback."""
    errors = [line for line in stderr.splitlines() if ": error: " in line]
    return len(errors) == 1 and text in errors[0] and "Traceback" not in stderr


def complete_run(out: Path) -> bool:
    """``out`` holds a whole `cardan run` output: the summary parses, the table is whole."""
    summary = json.loads((out / "summary.json").read_text())
    rows = (out / "timeseries.csv").read_text().splitlines()
    return summary["status"] == "ok" and len(rows) == summary["steps"] + 2  # header + steps + 1


@pytest.fixture
def previous(tmp_path) -> tuple[Path, dict[str, bytes]]:
    """``tmp_path/out``: the output of an earlier run, and its content."""
    out = tmp_path / "out"
    assert main([*QUICK, "--out", str(out)]) == 0
    return out, snapshot(out)


def test_exchange_swaps_two_folders(tmp_path):
    """renameat2(RENAME_EXCHANGE) is available here and swaps two non-empty folders in one step."""
    a, b = tmp_path / "a", tmp_path / "b"
    a.mkdir(), b.mkdir()
    (a / "x").write_text("a"), (b / "y").write_text("b")
    assert cio.exchange(a, b), "no atomic exchange on this system: the two-rename fallback is used"
    assert [p.name for p in a.iterdir()] == ["y"] and [p.name for p in b.iterdir()] == ["x"]
    with pytest.raises(FileNotFoundError):
        cio.exchange(a, tmp_path / "missing")


@pytest.mark.parametrize("exchange", [True, False], ids=["exchange", "two-renames"])
def test_replace_keeps_no_sibling(tmp_path, monkeypatch, previous, exchange):
    """Either way of swapping leaves the new output in place and nothing next to it."""
    out, _ = previous
    if not exchange:
        monkeypatch.setattr(cio, "exchange", lambda a, b: False)
    with cio.atomic_directory(out) as new:
        assert new.parent == out.parent and new.name.startswith(f".{out.name}.cardan-new-{os.getpid()}-")
        (new / "new.txt").write_text("new")
    assert [p.name for p in out.iterdir()] == ["new.txt"] and siblings(out) == []


def test_exchange_failure_keeps_previous(tmp_path, monkeypatch, previous):
    """An exchange that fails leaves the previous output and removes the new one."""
    out, before = previous

    def fail(a, b):
        raise OSError(errno.EIO, "I/O error")

    monkeypatch.setattr(cio, "exchange", fail)
    with pytest.raises(OSError, match="I/O error"), cio.atomic_directory(out) as new:
        (new / "new.txt").write_text("new")
    assert snapshot(out) == before and siblings(out) == []


@pytest.mark.parametrize("seed", range(4))
def test_kill_at_a_random_instant_leaves_previous_or_new(tmp_path, previous, seed):
    """SIGKILL `cardan run --out` at a random instant: the folder is the complete previous output
    or the complete new one, never neither; the next run removes what the killed one left."""
    out, before = previous
    proc = start([*LONG, "--out", str(out)], tmp_path)
    wait_for(lambda: (tmp_path / ".out.lock").exists(), proc)  # the command has started
    time.sleep(random.Random(seed).uniform(0.0, 3.0))
    os.killpg(proc.pid, signal.SIGKILL)
    proc.communicate()
    assert snapshot(out) == before or complete_run(out)
    assert main([*QUICK, "--out", str(out)]) == 0
    assert complete_run(out) and siblings(out) == []


SWAPPER = """
import itertools, sys
import cardan_exudyn.outputs as cio
if sys.argv[2] == "two-renames":
    cio.exchange = lambda a, b: False
for i in itertools.count():
    with cio.atomic_directory(sys.argv[1]) as new:
        for name in ("a", "b", "c"):
            (new / name).write_text(str(i) * 20000)
    print(i, flush=True)
"""


def consistent(out: Path) -> bool:
    """``out`` holds the three files of one iteration of SWAPPER, whole."""
    texts = {p.name: p.read_text() for p in out.iterdir()}
    return sorted(texts) == ["a", "b", "c"] and len(set(texts.values())) == 1 and len(texts["a"]) > 0


@pytest.mark.parametrize("how", ["exchange", "two-renames"])
def test_swaps_killed_at_random_instants(tmp_path, how):
    """A process replacing one folder over and over, SIGKILLed at random instants (every phase:
    new folder, writing, fsync, swap, removal of the previous): the folder is always one whole
    output; with two renames, after the next command's cleanup (which puts a previous output
    that a kill left aside back)."""
    out = tmp_path / "out"
    rng = random.Random(how)
    for _ in range(10):  # a swap that removes before it renames is caught in 1 kill of 5 here
        proc = subprocess.Popen([sys.executable, "-c", SWAPPER, str(out), how], stdout=subprocess.PIPE,
                                start_new_session=True)
        proc.stdout.readline()  # one swap done: about 60 ms each here, with the fsyncs
        time.sleep(rng.uniform(0.0, 0.3))
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
        if how == "exchange":
            assert consistent(out)
        cio.clean_leftovers(out)
        assert consistent(out) and siblings(out) in ([], [".out.lock"])


def test_leftovers_of_killed_commands_are_removed(tmp_path, previous):
    """Temporary folders of dead processes go, those of a live one stay, others' names are kept."""
    out, _ = previous
    dead, alive = dead_pid(), os.getpid()
    left = [f".out.cardan-new-{dead}-0a1b", f".out.cardan-old-{dead}-2c3d", f".out.cardan-new-{alive}-4e5f",
            ".out.settings", ".outer.cardan-new-1-00"]
    for name in left:
        (tmp_path / name).mkdir()
        (tmp_path / name / "f").write_text("x")
    removed = cio.clean_leftovers(out)
    assert sorted(p.name for p in removed) == sorted(left[:2])
    assert sorted(siblings(out)) == sorted([left[2], left[3]]) and (tmp_path / left[4]).is_dir()


def test_previous_output_put_aside_by_a_killed_swap_comes_back(tmp_path, previous):
    """Without an atomic exchange a kill between the two renames leaves the previous output at
    `.out.cardan-old-PID-*`: the next command puts it back before anything else."""
    out, before = previous
    os.rename(out, tmp_path / f".out.cardan-old-{dead_pid()}-00ff")
    assert not out.exists()
    cio.clean_leftovers(out)
    assert snapshot(out) == before and siblings(out) == []


def test_second_writer_is_refused_while_the_first_runs(tmp_path, capsys, previous):
    """A second command writing the same --out is refused in one line while the first runs; the
    first finishes and writes its output; the lock file goes with it."""
    out, before = previous
    proc = start([*LONG, "--out", str(out)], tmp_path)
    wait_for(lambda: (tmp_path / ".out.lock").exists(), proc)
    capsys.readouterr()
    assert main([*QUICK, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert one_error_line(err, "being written by another cardan command"), err
    assert f"process {proc.pid}" in err
    assert snapshot(out) == before
    _, stderr = proc.communicate(timeout=120)
    assert proc.returncode == 0, stderr
    assert complete_run(out) and siblings(out) == []


def test_second_sweep_is_refused(tmp_path, capsys):
    """Two sweeps into one folder: the second is refused while the first holds it."""
    out = tmp_path / "sw"
    argv = ["sweep", "--scene", "paper-literal-35deg", "--engine", "reference", "--set", "revolutions=2",
            "--grid", "load.torque=1,2,3,4,5,6", "--workers", "1", "--quiet", "--out", str(out)]
    proc = start(argv, tmp_path)
    wait_for(lambda: (tmp_path / ".sw.lock").exists(), proc)
    assert main(argv) == 2
    assert "being written by another cardan command" in capsys.readouterr().err
    _, stderr = proc.communicate(timeout=120)
    assert proc.returncode == 0, stderr


def test_lock_of_a_killed_writer_does_not_block(tmp_path, previous):
    """A writer killed with SIGKILL leaves its lock file, but not its lock."""
    out, _ = previous
    proc = start([*LONG, "--out", str(out)], tmp_path)
    wait_for(lambda: (tmp_path / ".out.lock").exists(), proc)
    os.killpg(proc.pid, signal.SIGKILL)
    proc.communicate()
    assert (tmp_path / ".out.lock").exists()
    assert main([*QUICK, "--out", str(out)]) == 0 and siblings(out) == []


def _file_size_limit(limit: int):
    def limit_writes() -> None:
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # a write beyond the limit fails with EFBIG

    return limit_writes


def test_full_disk_is_one_line_and_keeps_previous(tmp_path, previous):
    """A write the disk refuses (here: over a 64 kB file size limit, EFBIG, as a full disk's
    ENOSPC) is one line, exit 2; the previous output stays and nothing is left next to it."""
    out, before = previous
    proc = start([*QUICK, "--out", str(out)], tmp_path, preexec_fn=_file_size_limit(64_000))
    _, stderr = proc.communicate(timeout=120)
    assert proc.returncode == 2, stderr
    assert one_error_line(stderr, "cannot write") and "File too large" in stderr, stderr
    assert snapshot(out) == before and siblings(out) == []


def test_no_space_left_in_process_is_one_line(tmp_path, monkeypatch, capsys, previous):
    """ENOSPC while the result files are written: one line, exit 2, previous output kept."""
    out, before = previous

    def full(result, folder):
        (folder / "summary.json").write_text("{")
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(folder / "timeseries.csv"))

    monkeypatch.setattr(cio, "write_result_files", full)
    capsys.readouterr()
    assert main([*QUICK, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert one_error_line(err, "No space left on device"), err
    assert snapshot(out) == before and siblings(out) == []


def test_sweep_full_disk_is_one_line(tmp_path):
    """A sweep whose records no longer fit: one line, exit 2, the records written are kept."""
    out = tmp_path / "sw"
    argv = ["sweep", "--scene", "paper-literal-35deg", "--engine", "reference", "--set", "revolutions=1",
            "--grid", "load.torque=1,2,3,4", "--workers", "1", "--quiet", "--out", str(out)]
    proc = start(argv, tmp_path, preexec_fn=_file_size_limit(8_000))
    _, stderr = proc.communicate(timeout=120)
    assert proc.returncode == 2, stderr
    assert one_error_line(stderr, "File too large"), stderr
    lines = (out / "cases.jsonl").read_bytes().split(b"\n")
    assert all(json.loads(line)["status"] == "ok" for line in lines[:-1])


@pytest.mark.parametrize("umask", [0o022, 0o027, 0o077])
def test_folder_and_files_follow_the_umask(tmp_path, umask):
    """The output folder and its files get the permissions the umask gives (not mkdtemp's 0700)."""
    out = tmp_path / "out"
    old = os.umask(umask)
    try:
        assert main([*QUICK, "--out", str(out)]) == 0
    finally:
        os.umask(old)
    assert out.stat().st_mode & 0o777 == 0o777 & ~umask
    assert {p.stat().st_mode & 0o777 for p in out.iterdir()} == {0o666 & ~umask}


def test_summary_claims_only_files_written(tmp_path, capsys):
    """With record.timeseries = false the run writes and names summary.json only."""
    scene = tmp_path / "scene.toml"
    scene.write_text('base = "paper-literal-35deg"\nrevolutions = 1\n[record]\ntimeseries = false\n')
    out = tmp_path / "out"
    capsys.readouterr()
    assert main(["run", "--scene", str(scene), "--engine", "reference", "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert [p.name for p in out.iterdir()] == ["summary.json"]
    assert f"wrote {out}/summary.json" in printed and "timeseries.csv" not in printed


@pytest.mark.parametrize("where", ["cwd", "cwd-parent", "home", "repository"])
def test_folders_that_are_never_replaced(tmp_path, monkeypatch, capsys, where):
    """The current folder, its parents, the home folder and a git repository are refused however
    they are spelt; nothing in them changes."""
    work = tmp_path / "home" / "work"
    (work / ".git").mkdir(parents=True)
    (work / "notes.txt").write_text("mine")
    monkeypatch.chdir(work)
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    target = {"cwd": work, "cwd-parent": tmp_path, "home": tmp_path / "home",
              "repository": tmp_path / "repo"}[where]
    if where == "repository":
        (target / ".git").mkdir(parents=True)
    before = snapshot(tmp_path)
    capsys.readouterr()
    assert main([*QUICK, "--out", str(target)]) == 2
    err = capsys.readouterr().err
    assert one_error_line(err, "would be replaced as a whole"), err
    assert snapshot(tmp_path) == before


def test_sweep_keeps_other_files_in_its_folder(tmp_path):
    """The sweep writes into its folder (not replaced): a folder holding other files is fine."""
    out = tmp_path / "sw"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    summary = run_sweep({"scene": "paper-literal-35deg", "engine": "reference", "fixed": {"revolutions": 1},
                         "grid": {"load.torque": [1, 2]}}, out, workers=1, progress=False)
    assert summary["ok"] == 2 and (out / "notes.txt").read_text() == "mine"
    assert siblings(out) == []


def test_a_symbolic_link_as_output_is_replaced_without_leftovers(tmp_path, previous):
    """`--out` naming a symbolic link to a folder: the link gives way to the new folder, the folder
    it pointed to is left as it was, and nothing is left next to the output."""
    out, before = previous
    kept = tmp_path / "kept"
    out.rename(kept)
    out.symlink_to(kept)
    assert main([*QUICK, "--out", str(out)]) == 0
    assert not out.is_symlink() and complete_run(out) and snapshot(kept) == before
    assert siblings(out) == []
