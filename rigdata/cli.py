"""``cardan rig``: inspect, measure and validate rig files; write synthetic ones.

Registered through the ``cardan.commands`` entry point (``cardan_exudyn`` never imports rigdata);
imported at every ``cardan`` start, so it reaches rigdata through the lazy package.
Exit status: 0 success; 2 bad input (one line); 3 a model run failed.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import warnings
from collections.abc import Callable
from typing import Any

import rigdata
from cardan_exudyn import arguments
from cardan_exudyn.arguments import EXIT_BAD_INPUT, EXIT_FAILED, EXIT_OK, BadInput
from cardan_exudyn.engines import EngineUnavailable
from cardan_exudyn.outputs import OutputError
from cardan_exudyn.report.format import number
from reference.results.summary import Status
from reference.scene.joint import PAIR_NAMES
from reference.scene.mapping import replace
from reference.scene.scene import Scene
from reference.scene.validation import SceneError
from rigdata.campaign import command as campaign_command
from rigdata.options import pairs, settings, shaft_angle, transducer_options, transducers
from rigdata.synthetic import command as synthetic_command

__all__ = ["register", "cmd_inspect", "cmd_measure", "cmd_validate"]

#: The input errors a ``rig`` command reports in one line with exit status 2.
BAD_INPUT = (SceneError, BadInput, OutputError, EngineUnavailable, FileNotFoundError, IsADirectoryError,
             PermissionError)




def _read(args: argparse.Namespace, raw: Any = None) -> rigdata.RigRecord:
    """The record of ``FILE`` (or of its table ``raw``, already read) with the file options; a
    refused option is :class:`BadInput`."""
    options = {"mapping": pairs(args.map, "--map") or None, "units": pairs(args.unit, "--unit") or None,
               "sensitivity": args.sensitivity, "pulses_per_rev": args.pulses_per_rev}
    try:
        if raw is None:
            return rigdata.read(args.file, format=args.format, **options)
        return rigdata.record_of_table(raw, **options)
    except rigdata.RigDataError:
        raise
    except ValueError as exc:  # read() refuses its arguments (a --map channel, ...) with ValueError
        raise BadInput(str(exc)) from None


def _signs(args: argparse.Namespace) -> dict[str, int]:
    """``--sign CHANNEL=-1``: the channels recorded with the opposite sign convention."""
    signs = {}
    for channel, text in pairs(args.sign, "--sign").items():
        if text not in ("-1", "+1", "1"):
            raise BadInput(f"--sign expects CHANNEL=-1 or CHANNEL=+1, got {channel}={text}")
        signs[channel] = int(text)
    return signs


def _one_line_warnings(command: str) -> Callable[..., None]:
    """A ``warnings.showwarning`` printing ``cardan rig COMMAND: warning: MESSAGE`` on stderr."""
    def show(message: Warning | str, *args: Any, **kwargs: Any) -> None:
        print(f"cardan rig {command}: warning: {message}", file=sys.stderr, flush=True)

    return show


def _draws(args: argparse.Namespace) -> int:
    """``--mc``: the Monte Carlo draws, 0 for the GUM only."""
    if args.mc < 0:
        raise BadInput(f"--mc must be >= 0 (0: GUM only), got {args.mc}")
    return args.mc


def _conditioning(args: argparse.Namespace) -> rigdata.Conditioning:
    """The conditioning settings from the options."""
    return settings(rigdata.Conditioning, cutoff_harmonics=args.cutoff_harmonics,
                     settle_revolutions=args.settle, derivative=args.derivative)


def _inspection(rec: rigdata.RigRecord) -> dict[str, Any]:
    """What ``inspect`` reports about a record."""
    reader = rec.provenance.get("reader")
    if isinstance(reader, dict):
        reader = f"{reader.get('name')} {reader.get('version')}"
    return {
        "file": str(rec.file), "format": rec.provenance.get("format"),
        "reader": reader, "samples": int(rec.time.size),
        "sample_rate": rec.sample_rate, "duration_s": rec.duration,
        "revolutions_in": rec.revolutions("in"), "revolutions_out": rec.revolutions("out"),
        "channels": {name: {"column": s.column, "unit": s.unit, "conversion": s.conversion,
                            "quantum": s.quantum, "mean": float(rec.channels[name].mean())}
                     for name, s in rec.sources.items()},
        "synthetic": bool(rec.provenance.get("synthetic")),
        "header": {k: str(v) for k, v in (rec.provenance.get("header") or {}).items()},
    }


def _held(raw: Any) -> dict[str, dict[str, Any]]:
    """Every column (variable, channel) of a file's table with its unit as written and its sample
    count."""
    return {name: {"unit": raw.units.get(name), "samples": int(values.size)}
            for name, values in raw.columns.items()}


def _print_held(held: dict[str, dict[str, Any]]) -> None:
    """The file's columns, one line each."""
    print(f"  {len(held)} columns in the file:")
    for name, c in held.items():
        print(f"    {name!r} [{c['unit'] or 'no unit'}], {c['samples']} samples")


def cmd_inspect(args: argparse.Namespace) -> int:
    """``cardan rig inspect``: channels, units, rate, duration, revolutions, and every column of a file."""
    raw = rigdata.read_table(args.file, format=args.format)
    info = {**_inspection(_read(args, raw)), "columns": _held(raw)}
    held = info["columns"]
    if args.json:
        print(json.dumps(info, indent=2))
        return EXIT_OK
    print(f"{info['file']}: {info['format']} ({info['reader']}), {info['samples']} samples at "
          f"{info['sample_rate']:.6g} Hz, {info['duration_s']:.4g} s, input "
          f"{info['revolutions_in']:.3f} revolutions, output {info['revolutions_out']:.3f}"
          + ("  [SYNTHETIC]" if info["synthetic"] else ""))
    for name, c in info["channels"].items():
        print(f"  {name:<11} <- {c['column']!r} [{c['unit']}] {c['conversion']}"
              + (f", resolution {math.degrees(c['quantum']):.3g} deg" if c["quantum"] else "")
              + f"; mean {c['mean']:.6g}")
    _print_held(held)
    return EXIT_OK


def cmd_measure(args: argparse.Namespace) -> int:
    """``cardan rig measure``: measured efficiency with its uncertainty (:func:`rigdata.measure`); exit 3
    with the reason when a check fails (:mod:`rigdata.checks`).
    """
    rec = _read(args)
    angle = 15.0 if args.angle is None else args.angle  # the paper's rig case
    try:
        m = rigdata.measure(rec, angle, conditioning=_conditioning(args), transducers=transducers(args),
                            monte_carlo=_draws(args), seed=args.seed, signs=_signs(args))
    except ValueError as exc:  # a --sign channel the record lacks
        if isinstance(exc, rigdata.RigDataError):
            raise
        raise BadInput(str(exc)) from None
    out = m.as_dict()
    status = EXIT_OK if m.status == Status.OK else EXIT_FAILED
    if args.json:
        print(json.dumps(out, indent=2))
        return status
    if m.status != Status.OK:
        print(f"{rec.file}: status {m.status}: {m.reason}")
        return status
    mc = m.measured.monte_carlo
    print(f"{rec.file}: efficiency {m.efficiency:.4f} +- {m.u:.4f} (standard uncertainty) over "
          f"{out['revolutions']} revolutions at {out['mean_speed_in']:.4g} rad/s, "
          f"{out['mean_torque_in']:.4g} N m"
          + (f"; Monte Carlo 95 % [{mc['interval_95'][0]:.4f}, {mc['interval_95'][1]:.4f}]" if mc else ""))
    return status


def _scene(args: argparse.Namespace, rec: rigdata.RigRecord) -> Scene:
    """The joint to drive: ``--scene`` (name or scene file) with ``--angle`` (``auto``: the recording's, from
    ``rec``) and ``--friction`` when given.
    """
    from rigdata.checks import recorded_shaft_angle  # rigdata's modules load when a rig command runs
    from rigdata.validation import as_scene

    base = as_scene(args.scene)
    changes: dict[str, Any] = {}
    if args.angle == "auto":
        recorded = recorded_shaft_angle(rec, _conditioning(args))
        changes["joint.geometry.shaft_angle_deg"] = math.degrees(recorded)
    elif args.angle is not None:
        changes["joint.geometry.shaft_angle_deg"] = args.angle
    if args.friction is not None:
        changes.update({f"joint.pairs.{p}.friction_coefficient": args.friction for p in PAIR_NAMES})
    return replace(base, **changes) if changes else base


def _engines(text: str) -> tuple[str, ...]:
    """``--engines A,B``: engines that take a measured drive (:data:`rigdata.MODEL_ENGINES`)."""
    engines = tuple(e.strip() for e in text.split(",") if e.strip())
    if not engines or any(e not in rigdata.MODEL_ENGINES for e in engines):
        raise BadInput(f"--engines takes reference and/or exudyn, got {text!r}")
    return engines


def _progress(args: argparse.Namespace) -> Callable[[str], None]:
    """Progress lines on stderr, none with ``--json``."""
    def say(line: str) -> None:
        if not args.json:
            print(f"cardan rig validate: {line}", file=sys.stderr, flush=True)

    return say


def _print_validation(s: dict[str, Any]) -> None:
    """One line per engine: computed against measured efficiency, their difference, significance; one per
    check that failed.
    """
    measured = f"{s['measured_efficiency']:.4f} +- {s['measured_efficiency_u']:.4f}"
    for engine, comp in s["computed"].items():
        cmp = s["comparisons"].get(engine, {})
        if comp.get("status") != Status.OK:  # no computed efficiency, no difference
            print(f"{engine}: status {comp.get('status')}: {comp.get('reason')}; measured {measured}")
            continue
        print(f"{engine}: computed {number(comp.get('mean_efficiency'), '.6f')}, measured {measured}; "
              f"difference {number(cmp.get('difference'), '.4f')}, significant (k=2): "
              f"{cmp.get('significant_k2', '-')}")
    for finding in s.get("checks", []):
        if finding["status"] != Status.OK:
            print(f"check {finding['check']}: {finding['status']}: {finding['message']}")


def cmd_validate(args: argparse.Namespace) -> int:
    """``cardan rig validate``: measured against computed efficiency and the report folder; exit 3 when an
    engine failed or the measurement is ``unphysical`` or ``inconsistent``.
    """
    engines = _engines(args.engines)
    arguments.out_folder(args.out)
    signs = _signs(args)
    rec = _read(args)
    scene = _scene(args, rec)
    with warnings.catch_warnings():
        warnings.simplefilter("always", rigdata.RigDataWarning)
        warnings.showwarning = _one_line_warnings("validate")
        try:
            v = rigdata.validate(rec, scene, engines, conditioning=_conditioning(args),
                                 transducers=transducers(args), monte_carlo=_draws(args), seed=args.seed,
                                 progress=_progress(args), signs=signs)
        except ValueError as exc:  # a --sign channel the record lacks
            if isinstance(exc, rigdata.RigDataError):
                raise
            raise BadInput(str(exc)) from None
    command = ["cardan", *args.argv] if hasattr(args, "argv") else None
    s = rigdata.write_report(v, args.out, command)
    if args.json:
        print(json.dumps(s, indent=2))
    else:
        _print_validation(s)
        print(f"wrote {args.out}/report.md", file=sys.stderr)
    return EXIT_OK if v.success and v.measurement_usable else EXIT_FAILED


def _file_options(p: argparse.ArgumentParser) -> None:
    """``FILE`` and how to read it (every rig command but ``synthetic``)."""
    p.add_argument("file", metavar="FILE", help="rig file: delimited text, LabVIEW .lvm, NI .tdms, MATLAB "
                                                "(.mat, v7.3), Parquet, Excel .xlsx or ASAM MDF 3/4")
    p.add_argument("--format", choices=("auto", "csv", "lvm", "tdms", "mat", "parquet", "xlsx", "mdf"),
                   default="auto", help="auto (default): binary formats by content, others by extension")
    p.add_argument("--map", action="append", metavar="CHANNEL=COLUMN",
                   help="map a column to time, torque_in, torque_out, speed_in, speed_out, angle_in, "
                        "angle_out (COLUMN as in the header)")
    p.add_argument("--unit", action="append", metavar="CHANNEL=UNIT",
                   help="unit of a channel where the file does not state it, e.g. speed_in=rpm")
    p.add_argument("--sensitivity", type=arguments.number("V/(N m)", positive=True), default=0.1,
                   help="torque output of the transducers for columns in volts (default 0.1, paper)")
    p.add_argument("--pulses-per-rev", type=arguments.count("--pulses-per-rev"), default=60,
                   help="speed pulses per revolution for count columns (default 60, paper)")
    p.add_argument("--json", action="store_true", help="print the result as JSON on stdout")


def _measure_options(p: argparse.ArgumentParser) -> None:
    """Shaft angle, conditioning, transducers, Monte Carlo (``measure``, ``validate``)."""
    p.add_argument("--angle", type=shaft_angle, default=None,
                   help="shaft angle [deg], or auto: the recording's own (Hooke's speed ratio fit) "
                        "(default: validate the scene's, measure 15, the paper's rig case)")
    p.add_argument("--sign", action="append", metavar="CHANNEL=-1",
                   help="a channel recorded with the opposite sign convention, e.g. torque_out=-1 "
                        "(refused without it when the output power comes out negative)")
    p.add_argument("--cutoff-harmonics", type=arguments.number("-", positive=True), default=10.0,
                   help="low-pass cut-off in input shaft harmonics (default 10)")
    p.add_argument("--settle", type=arguments.number("rev", non_negative=True), default=0.25,
                   help="input revolutions dropped at each end (default 0.25)")
    p.add_argument("--derivative", choices=("savgol", "spline"), default="savgol")
    transducer_options(p)
    p.add_argument("--mc", type=arguments.count("--mc", minimum=0), default=2000,
                   help="Monte Carlo draws for the uncertainty (default 2000; 0: GUM only; at most "
                        f"{arguments.COUNT_LIMITS['--mc']})")
    p.add_argument("--seed", type=arguments.count("--seed", minimum=0), default=0,
                   help="seed of the Monte Carlo draws")


def _validate_options(p: argparse.ArgumentParser) -> None:
    """The report folder, the joint, its friction and the engines (``validate``)."""
    p.add_argument("--out", required=True, metavar="DIR", help="report folder (replaced atomically)")
    p.add_argument("--scene", default="rig", metavar="NAME|FILE",
                   help="the joint: a named scene or a scene TOML file (your own joint; may start "
                        "from base = \"rig\"); its drive and load are replaced by the "
                        "measurement's (default rig: the physical parameter set)")
    p.add_argument("--friction", type=arguments.number("-", non_negative=True),
                   help="friction coefficient of every pair (default: the scene's, 0.42 for the rig)")
    p.add_argument("--engines", default="reference,exudyn", help="reference and/or exudyn")


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``rig`` to the ``cardan`` command's subparsers."""
    p = sub.add_parser("rig", help="rig measurements: inspect, measure, validate against the model",
                       description="Measured efficiency from transducer files and its comparison "
                                   "with the model driven by the measurement (the paper's Figure 10).")
    rig = p.add_subparsers(dest="rig_command", required=True)
    commands = [
        ("inspect", "what a file holds: channels, units, rate, duration, revolutions", cmd_inspect,
         (_file_options,)),
        ("measure", "measured efficiency over whole revolutions with its uncertainty", cmd_measure,
         (_file_options, _measure_options)),
        ("validate", "measured against computed efficiency: report like Figure 10", cmd_validate,
         (_file_options, _measure_options, _validate_options)),
        ("synthetic", "write a synthetic rig file (labelled as such)", synthetic_command.cmd_synthetic,
         (synthetic_command.add_options,)),
        ("campaign", "calibrate on some recordings, validate on the others: model error with its "
                     "V&V 20 uncertainty", campaign_command.cmd_campaign, (campaign_command.add_options,)),
    ]
    for name, help_text, handler, options in commands:
        q = rig.add_parser(name, help=help_text)
        for add in options:
            add(q)
        q.set_defaults(func=_guarded(handler))


def _guarded(func: Callable[[argparse.Namespace], int]) -> Callable[[argparse.Namespace], int]:
    """Bad input of any kind -> one line on stderr, exit 2, no traceback."""
    def run(args: argparse.Namespace) -> int:
        try:
            return func(args)
        except (rigdata.RigDataError, *BAD_INPUT) as exc:
            print(f"cardan rig {args.rig_command}: error: {exc}", file=sys.stderr)
            return EXIT_BAD_INPUT

    return run
