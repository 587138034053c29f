"""Bad input at every entry point: the cases that ``tests/test_hardening.py`` runs.

Every entry point must reject bad input with one clear line naming what is wrong: the ``cardan``
command line (every subcommand, ``cardan rig ...`` included) exits with status 2, one line on
stderr, nothing on stdout, no traceback, and leaves an output folder it was given as it was; the
Python API raises a documented exception (:class:`~reference.scene.validation.SceneError`,
:class:`~cardan_exudyn.sweep.SweepError`, :class:`~cardan_exudyn.engines.EngineUnavailable`,
:class:`~cardan_exudyn.outputs.OutputError`, ``ValueError``; ``rigdata``'s ``RigDataError``) with a
one-line message. A run that fails is not bad input: it exits with status 3 and a status line
with its reason, and prints no NaN or infinite efficiency (nor does a run with no input work,
whose efficiency is 0/0: it says "undefined").

:data:`CASES` lists the cases: scene files, command-line options, Python API calls, rig files,
sweep specifications, run failures. Every case is fast (no long simulation). Add a case here and
``pytest tests/test_hardening.py`` runs it under its id.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from cardan_exudyn import ExudynOptions
from cardan_exudyn.comparison import compare
from cardan_exudyn.engines import EngineUnavailable, get_engine, run
from cardan_exudyn.outputs import OutputError, write_result
from cardan_exudyn.sweep import Distribution, SweepError, run_sweep, spec_from_mapping
from reference.engine.options import ReferenceOptions
from reference.paper.scenes import named_scene
from reference.results.result import Result
from reference.results.summary import OptionsError, Status, Summary
from reference.scene.files import load_scene
from reference.scene.joint import Body
from reference.scene.load import Load
from reference.scene.mapping import replace, scene_from_dict
from reference.scene.scene import Scene
from reference.scene.validation import SceneError
from rigdata.conditioning import Conditioning
from rigdata.measurement import measure
from rigdata.readers import read
from rigdata.record import ChannelSource, RigDataError, RigRecord
from rigdata.synthetic import RigSettings
from rigdata.synthetic import write as synthetic_write
from rigdata.transducer import Transducer
from rigdata.validation import validate

__all__ = ["CASES", "Case", "DIRECTORY", "ENTRY_POINTS", "MARKER"]

#: Entry points, in the order of :data:`CASES`.
ENTRY_POINTS = ("scene file", "cli", "python api", "rig file", "sweep spec", "run failure")
#: Content of ``Case.files`` that makes a folder instead of a file.
DIRECTORY = object()
#: What an output folder (or file) given to a command holds before the command runs.
MARKER = "previous output\n"


@dataclass(frozen=True)
class Case:
    """One bad input and what must happen.

    Attributes
    ----------
    id : str
        Short unique name: the test id and the case's folder.
    entry : str
        One of :data:`ENTRY_POINTS`.
    description : str
        What is wrong with the input, in words.
    argv : tuple of str
        ``cardan`` arguments (run through :func:`cardan_exudyn.cli.main`); ``{d}`` is replaced by
        the case folder, ``{out}`` by the output given to the command.
    call : callable, optional
        Python API case instead of ``argv``: ``call(folder)`` must raise ``expect``.
    files : mapping of str to str, bytes or DIRECTORY
        Files the case creates in its folder first.
    out : {"folder", "file"} or None
        The command is given ``{out}``: an existing folder holding ``marker.txt`` (or a file)
        with :data:`MARKER`, which must be left exactly as it was, with no temporary sibling.
    expect : int or exception type
        Exit status of the command line (2 bad input, 3 failed run, 0 a run that must print no
        non-finite number), or the exception type the call must raise.
    match : str
        Key word(s) the message must contain (case-insensitive).
    """

    id: str
    entry: str
    description: str
    argv: tuple[str, ...] = ()
    call: Callable[[Path], Any] | None = None
    files: Mapping[str, Any] = field(default_factory=dict)
    out: str | None = None
    expect: Any = 2
    match: str = ""

    def __post_init__(self) -> None:
        if self.entry not in ENTRY_POINTS:
            raise ValueError(f"case {self.id}: `entry` must be one of {ENTRY_POINTS}, got {self.entry!r}")
        if (self.call is None) == (not self.argv):
            raise ValueError(f"case {self.id}: give either `argv` or `call`")
        if self.out not in (None, "folder", "file"):
            raise ValueError(f"case {self.id}: `out` must be 'folder', 'file' or None, got {self.out!r}")

    @property
    def input(self) -> str:
        """The input as a failure message shows it."""
        if self.argv:
            return "cardan " + " ".join(a.replace("{d}/", "").replace("{out}", "OUT") for a in self.argv)
        return self.call.__doc__.strip().splitlines()[0] if self.call.__doc__ else self.call.__name__


# Inputs

_PAPER = 'base = "paper-literal"\n'
_PAPER_FRICTIONLESS = 'base = "paper-literal-frictionless"\n'
RIG_HEADER = "time [s],torque_in [N m],torque_out [N m],speed_in [rad/s],speed_out [rad/s]\n"


def _rig_csv(rows: int = 150, dt: float = 0.01, header: str = RIG_HEADER,
             row: Callable[[int, float], str] | None = None, end: str = "\n") -> str:
    """A small rig CSV at 6 rad/s (1.5 s: 1.4 input revolutions); ``row(k, t)`` overrides a line."""
    lines = [row(k, k * dt) if row is not None else f"{k * dt:.4f},0.2,0.19,6,6" for k in range(rows)]
    return header + "\n".join(lines) + end


def _mixed_rate(k: int, t: float) -> str:
    t = k * 0.01 if k < 75 else 0.75 + (k - 75) * 0.02
    return f"{t:.4f},0.2,0.19,6,6"


def _scene_toml(text: str) -> dict[str, str]:
    return {"scene.toml": text}


def _spec(text: str) -> dict[str, str]:
    return {"spec.toml": text}


_SWEEP = ("sweep", "{d}/spec.toml", "--out", "{out}", "--workers", "1", "--quiet")
_RIG_FILE = {"rig.csv": _rig_csv()}


# Python API calls (the first line of each docstring is the case's input)


def _api_load_missing(d: Path) -> Any:
    """reference.scene.files.load_scene("missing.toml")"""
    return load_scene(d / "missing.toml")


def _api_empty_dict(d: Path) -> Any:
    """reference.scene.mapping.scene_from_dict({})"""
    return scene_from_dict({})


def _api_replace_nan(d: Path) -> Any:
    """replace(scene, **{"joint.geometry.shaft_angle": nan})"""
    return replace(named_scene("paper-literal"), **{"joint.geometry.shaft_angle": math.nan})


def _api_replace_unknown(d: Path) -> Any:
    """replace(scene, **{"joint.nope.x": 1})"""
    return replace(named_scene("paper-literal"), **{"joint.nope.x": 1})


def _api_body_unphysical(d: Path) -> Any:
    """Body(1.0, diag(1, 1, 5)): violates the triangle inequality of inertia"""
    return Body(1.0, [[1, 0, 0], [0, 1, 0], [0, 0, 5]])


def _api_load_text(d: Path) -> Any:
    """Load(torque=[1, "a"], time=[0, 1])"""
    return Load(torque=[1.0, "a"], time=[0.0, 1.0])


def _api_named_unknown(d: Path) -> Any:
    """reference.paper.scenes.named_scene("nope")"""
    return named_scene("nope")


def _api_engine_unknown(d: Path) -> Any:
    """cardan_exudyn.engines.get_engine("warp")"""
    return get_engine("warp")


def _api_tiny_step(d: Path) -> Any:
    """cardan_exudyn.engines.run(paper-frictionless with numerics.dt = 1e-12, "reference")"""
    return run(replace(named_scene("paper-literal-frictionless"), **{"numerics.dt": 1e-12}), "reference")


def _api_compare_unknown(d: Path) -> Any:
    """compare(scene, ["exudyn", "warp"]): refused before any engine runs"""
    return compare(named_scene("paper-literal-frictionless"), ["exudyn", "warp"])


def _api_spec_empty_grid(d: Path) -> Any:
    """spec_from_mapping({"scene": "paper-literal", "grid": {"revolutions": []}})"""
    return spec_from_mapping({"scene": "paper-literal", "grid": {"revolutions": []}})


def _api_sweep_out_of_range(d: Path) -> Any:
    """run_sweep({"scene": "paper-literal", "grid": {"joint.geometry.shaft_angle_deg": [10, 95]}}, OUT)"""
    return run_sweep({"scene": "paper-literal", "engine": "reference",
                      "grid": {"joint.geometry.shaft_angle_deg": [10, 95]}}, d / "out", workers=1)


def _api_distribution(d: Path) -> Any:
    """Distribution("normal", mean=0, std=0)"""
    return Distribution("normal", mean=0.0, std=0.0)


def _api_write_result_file(d: Path) -> Any:
    """cardan_exudyn.outputs.write_result(result, "a-file"): the target exists and is not a folder"""
    return write_result(Result(None, Summary(Status.OK)), d / "out")


def _api_reference_options(d: Path) -> Any:
    """ReferenceOptions(quadrature_rtol=-1)"""
    return ReferenceOptions(quadrature_rtol=-1.0)


def _api_exudyn_options(d: Path) -> Any:
    """ExudynOptions(node_type="warp")"""
    return ExudynOptions(node_type="warp")


def _rig_read_empty(d: Path) -> Any:
    """rigdata.readers.read("empty.csv")"""
    return read(d / "empty.csv")


def _rig_read_mapping(d: Path) -> Any:
    """rigdata.readers.read("rig.csv", mapping={"foo": "bar"})"""
    return read(d / "rig.csv", mapping={"foo": "bar"})


def _rig_record_repeated_time(d: Path) -> Any:
    """RigRecord with time 0, 1, 1, 2"""
    channels = {c: np.ones(4) for c in ("torque_in", "torque_out", "speed_in", "speed_out")}
    return RigRecord(np.array([0.0, 1.0, 1.0, 2.0]), channels,
                     {c: ChannelSource(c, "SI") for c in channels})


def _rig_settings_huge(d: Path) -> Any:
    """rigdata.synthetic.RigSettings(revolutions=1e9)"""
    return RigSettings(revolutions=1e9)


def _api_run_none(d: Path) -> Any:
    """cardan_exudyn.engines.run(None, "reference")"""
    return run(None, "reference")


def _api_run_scene_name(d: Path) -> Any:
    """cardan_exudyn.engines.run("paper-literal", "reference"): a name where a Scene is expected"""
    return run("paper-literal", "reference")


def _api_run_engine_list(d: Path) -> Any:
    """cardan_exudyn.engines.run(scene, ["reference"]): a list where an engine name is expected"""
    return run(named_scene("paper-literal-frictionless"), ["reference"])


def _api_compare_string(d: Path) -> Any:
    """compare(scene, "exudyn,reference"): one string, not a list of engines"""
    return compare(named_scene("paper-literal-frictionless"), "exudyn,reference")


def _api_compare_none(d: Path) -> Any:
    """compare(None, ["exudyn", "reference"])"""
    return compare(None, ["exudyn", "reference"])


def _api_compare_skip_all(d: Path) -> Any:
    """compare(one-revolution scene, skip_revolutions=5): nothing left to compare"""
    return compare(replace(named_scene("paper-literal-frictionless"), revolutions=1.0), ["reference",
                                                                                         "exudyn"],
                   skip_revolutions=5.0)


def _api_replace_none(d: Path) -> Any:
    """reference.scene.mapping.replace(None, revolutions=2)"""
    return replace(None, revolutions=2.0)


def _api_scene_load_type(d: Path) -> Any:
    """Scene(joint, drive, load=5): a number where a Load is expected"""
    scene = named_scene("paper-literal")
    return Scene(scene.joint, scene.drive, load=5)


def _api_named_scene_list(d: Path) -> Any:
    """reference.paper.scenes.named_scene(["paper-literal"])"""
    return named_scene(["paper-literal"])


def _api_load_scene_none(d: Path) -> Any:
    """reference.scene.files.load_scene(None)"""
    return load_scene(None)


def _api_rig_read_none(d: Path) -> Any:
    """rigdata.readers.read(None)"""
    return read(None)


def _api_rig_measure_draws(d: Path) -> Any:
    """rigdata.measure("rig.csv", monte_carlo=10**10)"""
    return measure(d / "rig.csv", monte_carlo=10**10)


def _api_rig_transducer_class(d: Path) -> Any:
    """rigdata.Transducer(accuracy_class=1e300)"""
    return Transducer(accuracy_class=1e300)


def _api_rig_validate_string(d: Path) -> Any:
    """rigdata.validate("rig.csv", "rig-literal", "reference,exudyn"): one string, not a tuple of engines"""
    return validate(d / "rig.csv", "rig-literal", "reference,exudyn", monte_carlo=0)


def _api_rig_conditioning_phase(d: Path) -> Any:
    """rigdata.Conditioning(phase="a")"""
    return Conditioning(phase="a")


def _api_rig_synthetic_settings(d: Path) -> Any:
    """rigdata.synthetic.write("x.csv", "csv", settings=5)"""
    return synthetic_write(d / "x.csv", "csv", 5)


# The cases, by entry point

CASES: tuple[Case, ...] = (
    # scene files
    Case("scene-toml-syntax", "scene file", "a table header without its closing bracket",
         ("scene", "--scene", "{d}/scene.toml"),
         files=_scene_toml('revolutions = 2\n[joint.geometry\nshaft_angle_deg = 3\n'),
         match="not valid TOML"),
    Case("scene-unknown-key", "scene file", "a key no scene has (`foo`)",
         ("scene", "--scene", "{d}/scene.toml"), files=_scene_toml(_PAPER + "foo = 1\n"),
         match="unknown key(s) ['foo']"),
    Case("scene-wrong-type", "scene file", "`revolutions` is a string",
         ("scene", "--scene", "{d}/scene.toml"), files=_scene_toml(_PAPER + 'revolutions = "two"\n'),
         match="`revolutions` must be a number"),
    Case("scene-bool-count", "scene file", "`record.every` is a boolean",
         ("scene", "--scene", "{d}/scene.toml"), files=_scene_toml(_PAPER + "[record]\nevery = true\n"),
         match="`every` must be an integer"),
    Case("scene-negative-mass", "scene file", "negative mass of the input shaft",
         ("run", "--scene", "{d}/scene.toml", "--out", "{out}"),
         files=_scene_toml(_PAPER + "[joint.input]\nmass = -1\n"), out="folder",
         match="`mass` must be positive"),
    Case("scene-nan-angle", "scene file", "shaft angle NaN",
         ("scene", "--scene", "{d}/scene.toml"),
         files=_scene_toml(_PAPER + "[joint.geometry]\nshaft_angle_deg = nan\n"), match="must be finite"),
    Case("scene-inf-load", "scene file", "infinite load torque",
         ("scene", "--scene", "{d}/scene.toml"), files=_scene_toml(_PAPER + "[load]\ntorque = inf\n"),
         match="`torque` must be finite"),
    Case("scene-angle-90", "scene file", "shaft angle 90 deg (the joint cannot transmit motion)",
         ("scene", "--scene", "{d}/scene.toml"),
         files=_scene_toml(_PAPER + "[joint.geometry]\nshaft_angle_deg = 90\n"), match="[0, 90) deg"),
    Case("scene-angle-negative", "scene file", "shaft angle -5 deg",
         ("scene", "--scene", "{d}/scene.toml"),
         files=_scene_toml(_PAPER + "[joint.geometry]\nshaft_angle_deg = -5\n"), match="[0, 90) deg"),
    Case("scene-missing-file", "scene file", "the scene file does not exist",
         ("run", "--scene", "{d}/missing.toml", "--out", "{out}"), out="folder",
         match="cannot read scene file"),
    Case("scene-directory", "scene file", "a folder where the scene file should be",
         ("scene", "--scene", "{d}/scene.toml"), files={"scene.toml": DIRECTORY}, match="is a directory"),
    Case("scene-binary", "scene file", "binary junk instead of TOML text",
         ("scene", "--scene", "{d}/scene.toml"), files={"scene.toml": b"\xff\xfe\x00\x01\x80junk"},
         match="not UTF-8 text"),
    Case("scene-no-joint", "scene file", "no `base` and neither `joint` nor `drive`",
         ("scene", "--scene", "{d}/scene.toml"), files=_scene_toml("revolutions = 2\n"),
         match="missing required key(s) ['drive', 'joint']"),
    Case("scene-history-text", "scene file", "a load history with a text sample",
         ("scene", "--scene", "{d}/scene.toml"),
         files=_scene_toml(_PAPER + '[load]\ntorque = [1, 2]\ntime = [0, "a"]\n'),
         match="load `time` must be"),
    Case("scene-unknown-base", "scene file", "`base` names no scene",
         ("scene", "--scene", "{d}/scene.toml"), files=_scene_toml('base = "nope"\n'),
         match="unknown scene name 'nope'"),
    Case("scene-drive-kind", "scene file", "drive kind `warp`",
         ("scene", "--scene", "{d}/scene.toml"), files=_scene_toml(_PAPER + '[drive]\nkind = "warp"\n'),
         match="`kind` must be one of"),
    Case("scene-angle-drive-short", "scene file",
         "an angle drive (replacing the base's speed drive) with two samples",
         ("scene", "--scene", "{d}/scene.toml"),
         files=_scene_toml(_PAPER + '[drive]\nkind = "angle"\ntime = [0, 1]\nangle = [0, 7]\n'),
         match="at least 4 numbers"),
    Case("scene-name-number", "scene file", "`name` is a number",
         ("scene", "--scene", "{d}/scene.toml"), files=_scene_toml(_PAPER + "name = 5\n"),
         match="`name` must be a string"),
    Case("scene-tiny-step", "scene file", "`numerics.dt` = 1e-12 s: 6e10 steps",
         ("run", "--scene", "{d}/scene.toml", "--out", "{out}"),
         files=_scene_toml(_PAPER_FRICTIONLESS + "[numerics]\ndt = 1e-12\n"), out="folder", match="steps"),
    Case("scene-speed-huge", "scene file", "an input speed of 1e300 rpm",
         ("scene", "--scene", "{d}/scene.toml"), files=_scene_toml(_PAPER + "[drive]\nspeed_rpm = 1e300\n"),
         match="at most 1e+12 in magnitude"),
    Case("scene-drive-typo", "scene file", "a misspelt drive key (`sped`): the message lists every key",
         ("scene", "--scene", "{d}/scene.toml"), files=_scene_toml(_PAPER + "[drive]\nsped = 100\n"),
         match="allowed: ['kind', 'speed', 'speed_rpm']"),
    Case("scene-iterations-huge", "scene file", "1e9 friction iterations per step",
         ("scene", "--scene", "{d}/scene.toml"),
         files=_scene_toml(_PAPER + "[friction]\nmax_iterations = 1000000000\n"), match="[2, 10000]"),
    Case("scene-section-number", "scene file", "a number where the load table should be",
         ("scene", "--scene", "{d}/scene.toml"), files=_scene_toml(_PAPER + "load = 5\n"),
         match="[load] must be a table"),
    # command-line options
    Case("run-rpm-huge", "cli", "an input speed of 1e300 rpm", ("run", "--rpm", "1e300"),
         match="at most 1e+12"),
    Case("tolerance-samples-huge", "cli", "1e9 Monte Carlo samples (out of memory)",
         ("tolerance", "montecarlo", "--samples", "1e9", "--out", "{out}"), out="folder",
         match="--samples: must be at most 100000"),
    Case("tolerance-montecarlo-engines", "cli", "--engines (the paper case's) given to montecarlo",
         ("tolerance", "montecarlo", "--engines", "exudyn", "--out", "{out}"), out="folder",
         match="--engines does not apply"),
    Case("tolerance-paper-scene-option", "cli", "a scene option given to the paper case (fixed scenes)",
         ("tolerance", "paper", "--angle", "5", "--out", "{out}"), out="folder",
         match="--angle does not apply"),
    Case("tolerance-paper-samples", "cli", "--samples given to the paper case",
         ("tolerance", "paper", "--samples", "5", "--out", "{out}"), out="folder",
         match="--samples does not apply"),
    Case("compare-skip-all", "cli", "--skip-revolutions beyond the run (nan columns before)",
         ("compare", "--engines", "reference,exudyn", "--revolutions", "1", "--skip-revolutions", "5",
          "--out", "{out}"), out="folder", match="leaves nothing"),
    Case("sweep-workers-huge", "cli", "1e12 workers",
         ("sweep", "--scene", "paper-literal", "--grid", "revolutions=1", "--workers", "1000000000000",
          "--out", "{out}"),
         out="folder", match="at most 1024"),
    Case("bench-repeats-huge", "cli", "1e12 timed repeats", ("bench", "--repeats", "1e12"),
         match="at most 1000"),
    Case("stress-workers-zero", "cli", "zero workers for the map",
         ("stress", "--workers", "0", "--out", "{out}"), match="must be >= 1"),
    Case("rig-mc-huge", "cli", "1e9 Monte Carlo draws (out of memory)",
         ("rig", "measure", "{d}/rig.csv", "--mc", "1e9"), files=_RIG_FILE,
         match="--mc: must be at most 100000"),
    Case("rig-accuracy-class-huge", "cli", "accuracy class 1e300 %",
         ("rig", "measure", "{d}/rig.csv", "--accuracy-class", "1e300"), files=_RIG_FILE,
         match="--accuracy-class: must be at most 100"),
    Case("rig-full-scale-huge", "cli", "a transducer full scale of 1e300 N m",
         ("rig", "measure", "{d}/rig.csv", "--full-scale", "1e300"), files=_RIG_FILE, match="`full_scale`"),
    Case("run-angle-text", "cli", "non-numeric shaft angle", ("run", "--angle", "abc"),
         match="argument --angle: expected a number"),
    Case("run-rpm-inf", "cli", "infinite speed", ("run", "--rpm=-inf"), match="expected a finite number"),
    Case("run-load-overflow", "cli", "a load torque that overflows to inf", ("run", "--load-torque", "1e400"),
         match="finite"),
    Case("run-friction-negative", "cli", "negative friction coefficient",
         ("run", "--friction-spider", "-0.1"),
         match="must be >= 0"),
    Case("run-engine-unknown", "cli", "unknown engine", ("run", "--engine", "warp", "--out", "{out}"),
         out="folder", match="must be one of"),
    Case("run-engine-friction", "cli", "MuJoCo asked for a scene with friction",
         ("run", "--name", "paper-literal", "--engine", "mujoco"), match="cannot"),
    Case("run-name-unknown", "cli", "unknown named scene", ("run", "--name", "nope"),
         match="unknown scene name"),
    Case("run-scene-and-name", "cli", "--scene and --name together",
         ("run", "--scene", "{d}/x.toml", "--name", "paper-literal"),
             match="not allowed with argument --scene"),
    Case("run-revolutions-short", "cli", "half a revolution (no whole revolution to average)",
         ("run", "--revolutions", "0.5"), match="`revolutions` must be at least"),
    Case("run-tiny-step", "cli", "--dt 1e-12 (6e10 steps)", ("run", "--dt", "1e-12", "--out", "{out}"),
         out="folder", match="steps"),
    Case("run-accuracy-range", "cli", "accuracy 2 (must be below 1)", ("run", "--accuracy", "2"),
         match="`accuracy` must be < 1"),
    Case("run-out-is-file", "cli", "--out names an existing file",
         ("run", "--revolutions", "1", "--out", "{out}"), out="file", match="not a folder"),
    Case("run-out-parent", "cli", "--out names a parent folder (`..`), which would be replaced",
         ("run", "--revolutions", "1", "--out", "{d}/x/.."), match="names no folder of its own"),
    Case("scene-name-empty", "cli", "empty scene name", ("scene", "--name", ""), match="unknown scene name"),
    Case("compare-one-engine", "cli", "one engine to compare", ("compare", "--engines", "exudyn"),
         match="at least two engines"),
    Case("compare-engine-unknown", "cli", "an unknown second engine (refused before the first runs)",
         ("compare", "--engines", "exudyn,warp", "--out", "{out}"), out="folder", match="must be one of"),
    Case("compare-engine-twice", "cli", "the same engine twice",
         ("compare", "--engines", "reference,reference"),
         match="twice"),
    Case("compare-skip-nan", "cli", "--skip-revolutions nan", ("compare", "--skip-revolutions", "nan"),
         match="finite"),
    Case("sweep-no-scene", "cli", "no spec and no --scene", ("sweep", "--out", "{out}"), out="folder",
         match="`scene` is required"),
    Case("sweep-grid-syntax", "cli", "--grid without `=`",
         ("sweep", "--scene", "paper-literal", "--grid", "revolutions", "--out", "{out}"), out="folder",
         match="must look like PATH=V1,V2"),
    Case("sweep-out-empty", "cli", "an empty --out (would be the current folder)",
         ("sweep", "--scene", "paper-literal", "--grid", "revolutions=1", "--out", ""),
             match="--out is empty"),
    Case("sweep-workers-scheduler", "cli", "--workers and --scheduler together",
         ("sweep", "--scene", "paper-literal", "--grid", "revolutions=1", "--workers", "2", "--scheduler",
          "tcp://127.0.0.1:1", "--out", "{out}"), match="not allowed with"),
    Case("sweep-workers-zero", "cli", "zero workers",
         ("sweep", "--scene", "paper-literal", "--grid", "revolutions=1", "--workers", "0", "--out", "{out}"),
         match="must be >= 1"),
    Case("tolerance-samples-zero", "cli", "zero Monte Carlo samples",
         ("tolerance", "montecarlo", "--samples", "0", "--out", "{out}"), match="must be >= 1"),
    Case("tolerance-error-bounds", "cli", "uniform distribution with low above high",
         ("tolerance", "montecarlo", "--error", "joint.errors.a1_mm=uniform:1:0", "--out", "{out}"),
         out="folder", match="`low` must be below `high`"),
    Case("tolerance-error-dist", "cli", "unknown distribution",
         ("tolerance", "montecarlo", "--error", "joint.errors.a1_mm=gauss:0:1", "--out", "{out}"),
         match="uniform:LOW:HIGH"),
    Case("tolerance-seed-negative", "cli", "negative seed",
         ("tolerance", "montecarlo", "--seed", "-1", "--samples", "2", "--out", "{out}"), out="folder",
         match="seed"),
    Case("tolerance-engines-unknown", "cli", "unknown engine in the paper case",
         ("tolerance", "paper", "--engines", "warp", "--out", "{out}"), out="folder",
             match="--engines"),
    Case("reproduce-workers-zero", "cli", "zero workers", ("reproduce", "--workers", "0", "--out", "{out}"),
         match="must be >= 1"),
    Case("reproduce-out-is-file", "cli", "--out names an existing file", ("reproduce", "--out", "{out}"),
         out="file", match="not a folder"),
    Case("bench-repeats-zero", "cli", "zero repeats", ("bench", "--repeats", "0"), match="must be >= 1"),
    Case("bench-scene-unknown", "cli", "unknown benchmark scene", ("bench", "--scenes", "nope"),
         match="must be among"),
    Case("bench-out-is-file", "cli", "--out names an existing file (refused before the benchmark runs)",
         ("bench", "--quick", "--out", "{out}"), out="file", match="not a folder"),
    Case("calibrate-unknown", "cli", "unknown parameter set", ("calibrate", "--set", "foo"),
         match="--set must be one of"),
    Case("calibrate-engine", "cli", "an engine a fit cannot use", ("calibrate", "--engine", "mujoco"),
         match="--engine must be one of"),
    Case("bench-scene-option-and-scenes", "cli", "a scene of the user's and a subset of the default ones",
         ("bench", "--name", "paper-10deg", "--scenes", "friction-10deg"), match="--scenes"),
    Case("bench-dt", "cli", "a step, which every configuration sets itself",
         ("bench", "--name", "paper-10deg", "--dt", "1e-4"), match="unrecognized arguments: --dt"),
    Case("bench-angle-alone", "cli", "a scene option without the scene it would change",
         ("bench", "--angle", "20"), match="--angle applies to the scene of --scene or --name"),
    Case("stress-angle", "cli", "a shaft angle, which every cell sets itself",
         ("stress", "--angle", "20", "--out", "{out}"), out="folder",
         match="unrecognized arguments: --angle"),
    Case("stress-scene-unknown", "cli", "a scene name that does not exist",
         ("stress", "--name", "paper-nothing", "--quick", "--out", "{out}"), out="folder",
         match="paper-nothing"),
    Case("stress-out-parent-file", "cli", "--out inside an existing file (refused before the map runs)",
         ("stress", "--quick", "--out", "{out}/sub"), out="file", match="not a folder"),
    Case("rig-map-channel", "cli", "--map to a channel that does not exist",
         ("rig", "measure", "{d}/rig.csv", "--map", "foo=bar"), files=_RIG_FILE, match="mapping"),
    Case("rig-seed-negative", "cli", "negative Monte Carlo seed",
         ("rig", "measure", "{d}/rig.csv", "--seed", "-3"), files=_RIG_FILE, match="--seed"),
    Case("rig-angle-range", "cli", "shaft angle 95 deg", ("rig", "measure", "{d}/rig.csv", "--angle", "95"),
         files=_RIG_FILE, match="--angle"),
    Case("rig-mc-negative", "cli", "negative Monte Carlo draws",
         ("rig", "measure", "{d}/rig.csv", "--mc", "-1"),
         files=_RIG_FILE, match="--mc"),
    Case("rig-format-unknown", "cli", "unknown file format",
         ("rig", "inspect", "{d}/rig.csv", "--format", "sav"),
         files=_RIG_FILE, match="invalid choice"),
    Case("rig-synthetic-out-dir", "cli", "synthetic --out names an existing folder",
         ("rig", "synthetic", "--out", "{out}"), out="folder", match="is a directory"),
    Case("rig-synthetic-huge", "cli", "1e9 revolutions of synthetic record",
         ("rig", "synthetic", "--revolutions", "1e9", "--out", "{out}"), out="file", match="samples"),
    Case("rig-validate-engine", "cli", "validate with an engine it does not take",
         ("rig", "validate", "{d}/rig.csv", "--engines", "mujoco", "--out", "{out}"), files=_RIG_FILE,
         out="folder", match="--engines"),
    Case("rig-validate-scene", "cli", "validate with an unknown scene",
         ("rig", "validate", "{d}/rig.csv", "--scene", "nope", "--out", "{out}"), files=_RIG_FILE,
         out="folder", match="unknown scene name"),
    Case("rig-validate-out-file", "cli", "validate --out names an existing file",
         ("rig", "validate", "{d}/rig.csv", "--out", "{out}"), files=_RIG_FILE, out="file",
         match="not a folder"),
    # Python API
    Case("api-load-missing", "python api", "load a scene file that does not exist", call=_api_load_missing,
         expect=SceneError, match="cannot read scene file"),
    Case("api-empty-scene", "python api", "a scene from an empty table", call=_api_empty_dict,
         expect=SceneError, match="missing required key(s)"),
    Case("api-replace-nan", "python api", "replace the shaft angle by NaN", call=_api_replace_nan,
         expect=SceneError, match="must be finite"),
    Case("api-replace-unknown", "python api", "replace a field that does not exist",
         call=_api_replace_unknown,
         expect=SceneError, match="unknown scene field"),
    Case("api-body-unphysical", "python api", "inertia that no body has", call=_api_body_unphysical,
         expect=SceneError, match="not physical"),
    Case("api-load-text", "python api", "a load history with a text sample", call=_api_load_text,
         expect=SceneError, match="load `torque` must be"),
    Case("api-named-unknown", "python api", "unknown named scene", call=_api_named_unknown,
         expect=SceneError, match="unknown scene name"),
    Case("api-engine-unknown", "python api", "unknown engine", call=_api_engine_unknown,
         expect=EngineUnavailable, match="must be one of"),
    Case("api-tiny-step", "python api", "a step that needs 6e10 samples", call=_api_tiny_step,
         expect=SceneError, match="steps"),
    Case("api-compare-unknown", "python api", "compare with an unknown engine", call=_api_compare_unknown,
         expect=EngineUnavailable, match="warp"),
    Case("api-spec-empty-grid", "python api", "sweep spec with an empty grid", call=_api_spec_empty_grid,
         expect=SweepError, match="empty list"),
    Case("api-sweep-out-of-range", "python api", "sweep whose grid leaves the scene's range",
         call=_api_sweep_out_of_range, out="folder", expect=SceneError, match="[0, 90) deg"),
    Case("api-distribution", "python api", "normal distribution with zero spread", call=_api_distribution,
         expect=SweepError, match="`std` must be positive"),
    Case("api-write-result-file", "python api", "write a result over an existing file",
         call=_api_write_result_file, out="file", expect=OutputError, match="not a folder"),
    Case("api-reference-options", "python api", "negative quadrature tolerance", call=_api_reference_options,
         expect=ValueError, match="quadrature_rtol"),
    Case("api-exudyn-options", "python api", "unknown node type", call=_api_exudyn_options,
         expect=OptionsError, match="node_type"),
    Case("api-rig-empty", "python api", "read an empty rig file", call=_rig_read_empty,
         files={"empty.csv": ""}, expect=RigDataError, match="empty file"),
    Case("api-rig-mapping", "python api", "read with a mapping to an unknown channel",
         call=_rig_read_mapping, files=_RIG_FILE, expect=ValueError, match="`mapping` keys"),
    Case("api-rig-record", "python api", "a record whose time repeats a value",
         call=_rig_record_repeated_time, expect=RigDataError,
         match="does not increase at sample 2 (1.0 "),
    Case("api-rig-settings", "python api", "a synthetic record of 1e12 samples",
         call=_rig_settings_huge, expect=ValueError, match="samples"),
    Case("api-run-none", "python api", "None where a scene is expected", call=_api_run_none,
         expect=TypeError, match="`scene` must be a Scene"),
    Case("api-run-scene-name", "python api", "a scene name where a Scene is expected",
         call=_api_run_scene_name, expect=TypeError, match="named_scene"),
    Case("api-run-engine-list", "python api", "a list where an engine name is expected",
         call=_api_run_engine_list, expect=TypeError, match="`engine` must be the name of an engine"),
    Case("api-compare-string", "python api", "engines as one comma-separated string",
         call=_api_compare_string, expect=TypeError, match="not one string"),
    Case("api-compare-none", "python api", "compare None", call=_api_compare_none, expect=TypeError,
         match="`scene` must be a Scene"),
    Case("api-compare-skip-all", "python api", "skip more revolutions than the scene has",
         call=_api_compare_skip_all, expect=ValueError, match="`skip_revolutions`"),
    Case("api-replace-none", "python api", "replace in None", call=_api_replace_none, expect=TypeError,
         match="`scene` must be a Scene"),
    Case("api-scene-load-type", "python api", "a number where a Load is expected", call=_api_scene_load_type,
         expect=TypeError, match="`load` must be a Load"),
    Case("api-named-scene-list", "python api", "a list as a scene name", call=_api_named_scene_list,
         expect=TypeError, match="`name` must be a scene name"),
    Case("api-load-scene-none", "python api", "None as a scene file", call=_api_load_scene_none,
         expect=TypeError, match="`path`"),
    Case("api-rig-read-none", "python api", "None as a rig file", call=_api_rig_read_none, expect=TypeError,
         match="`path`"),
    Case("api-rig-measure-draws", "python api", "1e10 Monte Carlo draws", call=_api_rig_measure_draws,
         files=_RIG_FILE, expect=ValueError, match="`monte_carlo` must be an integer in [0, 100000]"),
    Case("api-rig-transducer-class", "python api", "accuracy class 1e300", call=_api_rig_transducer_class,
         expect=ValueError, match="`accuracy_class` must be at most 1"),
    Case("api-rig-validate-string", "python api", "engines as one string", call=_api_rig_validate_string,
         files=_RIG_FILE, expect=TypeError, match="not one string"),
    Case("api-rig-conditioning-phase", "python api", "a text phase", call=_api_rig_conditioning_phase,
         expect=TypeError, match="`phase` must be a number"),
    Case("api-rig-synthetic-settings", "python api", "a number as the settings",
         call=_api_rig_synthetic_settings, expect=TypeError, match="`settings` must be a RigSettings"),
    # rig files
    Case("rig-empty", "rig file", "empty file", ("rig", "inspect", "{d}/rig.csv"), files={"rig.csv": ""},
         match="empty file"),
    Case("rig-truncated", "rig file", "the last line cut short, no line end",
         ("rig", "inspect", "{d}/rig.csv"),
         files={"rig.csv": _rig_csv(end="\n1.5000,0.2")}, match="truncated"),
    Case("rig-wrong-columns", "rig file", "no column names a torque",
         ("rig", "inspect", "{d}/rig.csv"),
         files={"rig.csv": _rig_csv(header="time [s],a [N m],b [N m],c,d\n")},
         match="missing: no column recognised as torque_in"),
    Case("rig-time-backwards", "rig file", "time steps back at sample 50", ("rig", "inspect", "{d}/rig.csv"),
         files={"rig.csv": _rig_csv(row=lambda k, t: f"{t - 0.2 * (k >= 50):.4f},0.2,0.19,6,6")},
         match="time does not increase at sample 50 (0.49 then 0.3)"),
    Case("rig-mixed-rate", "rig file", "the sampling interval doubles halfway",
         ("rig", "inspect", "{d}/rig.csv"),
         files={"rig.csv": _rig_csv(row=_mixed_rate)}, match="mixed sampling rates"),
    Case("rig-binary", "rig file", "binary junk", ("rig", "inspect", "{d}/rig.csv"),
         files={"rig.csv": bytes(range(256)) * 8}, match="not a text file"),
    Case("rig-extension-tdms", "rig file", "delimited text named .tdms", ("rig", "inspect", "{d}/rig.tdms"),
         files={"rig.tdms": _rig_csv()}, match="not a TDMS file"),
    Case("rig-extension-lvm", "rig file", "delimited text named .lvm", ("rig", "inspect", "{d}/rig.lvm"),
         files={"rig.lvm": _rig_csv()}, match="not a LabVIEW Measurement file"),
    Case("rig-header-only", "rig file", "a header and no data", ("rig", "inspect", "{d}/rig.csv"),
         files={"rig.csv": RIG_HEADER}, match="no data rows"),
    Case("rig-nan", "rig file", "NaN in the output torque", ("rig", "inspect", "{d}/rig.csv"),
         files={"rig.csv": _rig_csv(row=lambda k, t: f"{t:.4f},0.2,{'nan' if k == 10 else 0.19},6,6")},
         match="non-finite"),
    Case("rig-text-cell", "rig file", "a word in the input torque", ("rig", "inspect", "{d}/rig.csv"),
         files={"rig.csv": _rig_csv(row=lambda k, t: f"{t:.4f},{'abc' if k == 10 else 0.2},0.19,6,6")},
         match="'abc'"),
    Case("rig-ragged", "rig file", "a row with a field missing", ("rig", "inspect", "{d}/rig.csv"),
         files={"rig.csv": _rig_csv(row=lambda k, t: f"{t:.4f},0.2,0.19,6" + ("" if k == 20 else ",6"))},
         match="line 22 has 4 fields"),
    Case("rig-duplicate-columns", "rig file", "two columns of the same name",
         ("rig", "inspect", "{d}/rig.csv"),
         files={"rig.csv": _rig_csv(header=RIG_HEADER.replace("torque_out", "torque_in"))},
         match="duplicate"),
    Case("rig-directory", "rig file", "a folder where the file should be", ("rig", "inspect", "{d}/rig.csv"),
         files={"rig.csv": DIRECTORY}, match="is a directory"),
    Case("rig-missing", "rig file", "the file does not exist", ("rig", "measure", "{d}/missing.csv"),
         match="missing.csv"),
    Case("rig-unit-mismatch", "rig file", "a speed unit given to a torque channel",
         ("rig", "inspect", "{d}/rig.csv", "--unit", "torque_in=rpm"), files=_RIG_FILE, match="speed unit"),
    Case("rig-still", "rig file", "the input shaft does not turn",
         ("rig", "measure", "{d}/rig.csv", "--mc", "0"),
         files={"rig.csv": _rig_csv(row=lambda k, t: f"{t:.4f},0.2,0.19,0,0")}, match="does not turn"),
    Case("rig-one-revolution", "rig file", "less than one whole revolution after settling",
         ("rig", "measure", "{d}/rig.csv", "--mc", "0"), files={"rig.csv": _rig_csv(rows=110)},
         match="less than one whole input revolution"),
    Case("rig-dead-torque-out", "rig file", "output torque 0 at every sample (unplugged transducer)",
         ("rig", "measure", "{d}/rig.csv", "--mc", "0"),
         files={"rig.csv": _rig_csv(rows=300, row=lambda k, t: f"{t:.4f},0.2,0,6,6")},
         match="channel 'torque_out': reads 0 at every sample"),
    Case("rig-dead-speed-out", "rig file", "output speed 0 at every sample (unplugged transducer)",
         ("rig", "measure", "{d}/rig.csv", "--mc", "0"),
         files={"rig.csv": _rig_csv(rows=300, row=lambda k, t: f"{t:.4f},0.2,0.19,6,0")},
         match="channel 'speed_out': reads 0 at every sample"),
    Case("rig-stuck-output", "rig file", "an output speed a thousand times too small (wrong scale)",
         ("rig", "measure", "{d}/rig.csv", "--mc", "0"),
         files={"rig.csv": _rig_csv(rows=300, row=lambda k, t: f"{t:.4f},0.2,0.19,6,0.006")},
         match="turn together"),
    Case("rig-ten-samples", "rig file", "a file of 10 samples",
         ("rig", "measure", "{d}/rig.csv", "--mc", "0"),
         files={"rig.csv": _rig_csv(rows=10)}, match="too short: 10 samples"),
    Case("rig-huge-torque", "rig file", "torques of 2e299 N m", ("rig", "inspect", "{d}/rig.csv"),
         files={"rig.csv": _rig_csv(row=lambda k, t: f"{t:.4f},2e299,1.9e299,6,6")},
         match="exceeds the plausible 1e+08 N m"),
    Case("rig-huge-time", "rig file", "times of 1e297 s and more", ("rig", "measure", "{d}/rig.csv"),
         files={"rig.csv": _rig_csv(row=lambda k, t: f"{k * 1e297:.4g},0.2,0.19,6,6")},
         match="channel 'time'"),
    # sweep specifications
    Case("spec-samples-huge", "sweep spec", "[random] samples = 1000000000 (out of memory)", _SWEEP,
         files=_spec('scene = "paper-literal"\n[random]\nsamples = 1000000000\nseed = 1\n'
                     '[random.parameters.revolutions]\ndist = "uniform"\nlow = 1\nhigh = 2\n'),
         out="folder", match="`random.samples` must be in [1, 100000]"),
    Case("spec-samples-float", "sweep spec", "[random] samples = 1e9 (a float)", _SWEEP,
         files=_spec('scene = "paper-literal"\n[random]\nsamples = 1e9\nseed = 1\n'
                     '[random.parameters.revolutions]\ndist = "uniform"\nlow = 1\nhigh = 2\n'),
         out="folder", match="`random.samples` must be an integer"),
    Case("spec-grid-huge", "sweep spec", "a grid of 1e5 x 1e5 points", _SWEEP,
         files=_spec('scene = "paper-literal"\n[grid]\nrevolutions = {linspace = [1, 2, 100000]}\n'
                     '"load.torque" = {linspace = [1, 2, 100000]}\n'), out="folder", match="at most 100000"),
    Case("spec-unknown-parameter", "sweep spec", "grid over a scene field that does not exist", _SWEEP,
         files=_spec('scene = "paper-literal"\nengine = "reference"\n[grid]\n'
                     '"joint.geometry.nope" = [1, 2]\n'),
         out="folder", match="unknown key(s) ['nope']"),
    Case("spec-empty-grid", "sweep spec", "a grid parameter with no values", _SWEEP,
         files=_spec('scene = "paper-literal"\n[grid]\nrevolutions = []\n'), out="folder",
             match="empty list"),
    Case("spec-bad-distribution", "sweep spec", "distribution `cauchy`", _SWEEP,
         files=_spec('scene = "paper-literal"\n[random]\nsamples = 3\nseed = 1\n'
                     '[random.parameters."joint.errors.a1_mm"]\ndist = "cauchy"\nlow = 0\nhigh = 1\n'),
         out="folder", match="`dist` must be one of"),
    Case("spec-toml-syntax", "sweep spec", "unclosed table header", _SWEEP,
         files=_spec('scene = "paper-literal"\n[grid\n'), out="folder", match="not valid TOML"),
    Case("spec-unknown-key", "sweep spec", "a top-level key no spec has", _SWEEP,
         files=_spec('scene = "paper-literal"\nfoo = 1\n[grid]\nrevolutions = [1]\n'), out="folder",
         match="unknown key(s) ['foo']"),
    Case("spec-no-seed", "sweep spec", "random samples without a seed", _SWEEP,
         files=_spec('scene = "paper-literal"\n[random]\nsamples = 3\n'
                     '[random.parameters.revolutions]\ndist = "uniform"\nlow = 1\nhigh = 2\n'),
         out="folder", match="`seed` is required"),
    Case("spec-cases-and-grid", "sweep spec", "explicit cases and a grid", _SWEEP,
         files=_spec('scene = "paper-literal"\ncases = [{revolutions = 1}]\n[grid]\nrevolutions = [1]\n'),
         out="folder",
         match="not both"),
    Case("spec-linspace-zero", "sweep spec", "linspace with zero points", _SWEEP,
         files=_spec('scene = "paper-literal"\n[grid]\nrevolutions = {linspace = [1, 2, 0]}\n'), out="folder",
         match="num must be an integer >= 1"),
    Case("spec-grid-out-of-range", "sweep spec", "a grid value outside the scene's range", _SWEEP,
         files=_spec('scene = "paper-literal"\n[grid]\n"joint.geometry.shaft_angle_deg" = [10, 95]\n'),
             out="folder",
         match="[0, 90) deg"),
    Case("spec-binary", "sweep spec", "binary junk instead of TOML", _SWEEP,
         files={"spec.toml": b"\xff\xfe\x00junk"}, out="folder", match="not UTF-8 text"),
    Case("spec-directory", "sweep spec", "a folder where the spec should be", _SWEEP,
         files={"spec.toml": DIRECTORY}, out="folder", match="is a directory"),
    Case("spec-duplicate-id", "sweep spec", "two cases with one id", _SWEEP,
         files=_spec('scene = "paper-literal"\n'
                     'cases = [{id = "a", revolutions = 1}, {id = "a", revolutions = 2}]\n'),
         out="folder", match="used twice"),
    Case("spec-missing", "sweep spec", "the spec file does not exist",
         ("sweep", "{d}/missing.toml", "--out", "{out}"), out="folder", match="cannot read sweep spec"),
    Case("spec-nothing", "sweep spec", "a scene and nothing to sweep", _SWEEP,
         files=_spec('scene = "paper-literal"\n'), out="folder", match="nothing to sweep"),
    Case("spec-engine-fixed", "sweep spec", "engine among the fixed overrides", _SWEEP,
         files=_spec('scene = "paper-literal"\n[fixed]\nengine = "reference"\n[grid]\nrevolutions = [1]\n'),
         out="folder", match="`engine` can be set"),
    Case("spec-scene-missing", "sweep spec", "the spec's scene file does not exist", _SWEEP,
         files=_spec('scene = "nope.toml"\n[grid]\nrevolutions = [1]\n'), out="folder",
         match="cannot read scene file"),
    # failures inside a run
    Case("fail-run-reference", "run failure", "self-locking at 50 deg, reference engine",
         ("run", "--name", "paper-literal-50deg", "--engine", "reference", "--revolutions", "1"), expect=3,
         match="status: self_locking"),
    Case("fail-run-exudyn", "run failure", "self-locking at 50 deg, Exudyn",
         ("run", "--name", "paper-literal-50deg", "--revolutions", "1"), expect=3,
             match="status: self_locking"),
    Case("fail-run-json", "run failure", "self-locking with --json: strict JSON, no efficiency",
         ("run", "--name", "paper-literal-50deg", "--engine", "reference", "--revolutions", "1", "--json"),
             expect=3,
         match='"status": "self_locking"'),
    Case("free-spin", "run failure", "a joint spinning free: no input work, the efficiency is 0/0",
         ("run", "--scene", "{d}/scene.toml"), expect=0, match="mean efficiency undefined",
         files=_scene_toml('base = "paper-literal-frictionless"\nrevolutions = 1\n[load]\ntorque = 0.0\n'
                           '[drive]\nkind = "torque"\ntorque = 0.0\ninitial_speed = 209.4\n')),
    Case("fail-compare", "run failure", "compare where both engines self-lock",
         ("compare", "--name", "paper-literal-50deg", "--engines", "reference,exudyn", "--revolutions", "1"),
         expect=3, match="self_locking"),
    Case("fail-sweep", "run failure", "a sweep whose case self-locks",
         ("sweep", "--scene", "paper-literal-50deg", "--engine", "reference", "--grid", "revolutions=1",
          "--workers", "1", "--out", "{d}/sweep"), expect=3, match="1 self_locking"),
    Case("fail-tolerance", "run failure", "Monte Carlo on a self-locking scene",
         ("tolerance", "montecarlo", "--name", "paper-literal-50deg", "--revolutions", "1", "--samples", "2",
          "--workers", "1", "--out", "{d}/mc"), expect=3, match="self_locking"),
)
