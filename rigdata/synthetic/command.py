"""``cardan rig synthetic``: write a labelled synthetic rig file, or a synthetic validation campaign
(its options and handler; imported at every ``cardan`` start, so it loads the generator only when run).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

import rigdata
from cardan_exudyn import arguments
from cardan_exudyn.arguments import EXIT_OK, BadInput
from rigdata.options import settings, shaft_angle, transducer_options, transducers

__all__ = ["SYNTHETIC_FORMATS", "DECIMAL_FORMATS", "synthetic_settings", "cmd_synthetic", "add_options"]

#: ``rigdata.synthetic.FORMATS``, spelled here so that parsing loads neither scipy nor pandas.
SYNTHETIC_FORMATS = ("csv", "lvm", "tdms", "mat", "parquet", "mdf")
#: The formats ``--decimal`` applies to (the others store numbers, not text).
DECIMAL_FORMATS = ("csv", "lvm")


def synthetic_settings(args: argparse.Namespace) -> rigdata.RigSettings:
    """The synthetic rig's settings from the options (``--rpm``/``--seconds`` converted to rad/s and
    revolutions: the file spans ``revolutions + 0.25``)."""
    speed = args.speed if args.rpm is None else args.rpm * 2.0 * math.pi / 60.0
    revolutions = args.revolutions
    if args.seconds is not None:
        revolutions = args.seconds * speed / (2.0 * math.pi) - 0.25
        if revolutions < 1.6:
            raise BadInput(f"--seconds {args.seconds:g} at {speed:g} rad/s is {revolutions + 0.25:.3g} "
                           f"revolutions; at least 1.85 are needed (1.6 after settling)")
    exact = {"offsets": (0.0, 0.0), "drifts": (0.0, 0.0)} if args.perfect else {}
    load = {"input_torque": args.input_torque} if args.load is None else {"load_torque": args.load}
    return settings(rigdata.RigSettings, scene=args.scene, shaft_angle_deg=args.angle, speed=speed,
                     friction=args.friction, rate=args.rate, noise=args.noise, revolutions=revolutions,
                     seed=1 if args.seed is None else args.seed, speed_channel=args.speed_channel,
                     torque_out_sign=args.torque_out_sign, drag_torque=args.drag_torque, **load, **exact)


def _synthetic_campaign(args: argparse.Namespace) -> int:
    """``cardan rig synthetic --campaign DIR``: the campaign's files and ``campaign.toml`` (its path on
    stdout)."""
    if Path(args.campaign).exists() and not Path(args.campaign).is_dir():
        raise BadInput(f"--campaign {args.campaign!r} is a file; give the folder to write the campaign in")
    options = {"friction": args.friction, "seed": args.seed, "seconds": args.seconds}
    try:
        path = rigdata.synthetic.write_campaign(
            args.campaign, drag_torque=args.drag_torque, rate=args.rate, scene=args.scene,
            **{k: v for k, v in options.items() if v is not None})
    except ValueError as exc:  # write_campaign refuses its settings with ValueError
        if isinstance(exc, rigdata.RigDataError):
            raise
        raise BadInput(str(exc)) from None
    print(path)
    return EXIT_OK


def cmd_synthetic(args: argparse.Namespace) -> int:
    """``cardan rig synthetic``: write a synthetic rig file, labelled as such with its settings, or with
    ``--campaign`` a synthetic validation campaign."""
    if args.campaign is not None:
        return _synthetic_campaign(args)
    out = Path(args.out)
    if out.is_dir():
        raise BadInput(f"--out {args.out!r} is a directory; give the name of the file to write")
    if not out.parent.is_dir():
        raise BadInput(f"--out {args.out!r}: the folder {str(out.parent)!r} does not exist")
    if args.decimal is not None and args.format not in DECIMAL_FORMATS:
        raise BadInput(f"--decimal applies to {' and '.join(DECIMAL_FORMATS)} files, "
                       f"got --format {args.format}")
    settings = synthetic_settings(args)
    transducer, _ = transducers(args)
    try:
        used = rigdata.synthetic.write(args.out, args.format, settings, transducer, decimal=args.decimal)
    except ValueError as exc:  # the model refuses the settings (a drag that leaves no brake torque)
        if isinstance(exc, rigdata.RigDataError):
            raise
        raise BadInput(str(exc)) from None
    if args.json:
        print(json.dumps(used, indent=2))
    else:
        print(f"wrote {args.out} (SYNTHETIC, {args.format}): true efficiency "
              f"{used['true_efficiency']:.6f}, brake {used['brake_torque']:.6g} N m, offsets "
              f"{used['offsets']} N m", file=sys.stderr)
    return EXIT_OK


def add_options(p: argparse.ArgumentParser) -> None:
    """The file to write and the synthetic rig's settings (``synthetic``)."""
    target = p.add_mutually_exclusive_group(required=True)
    target.add_argument("--out", metavar="FILE", help="the file to write")
    target.add_argument("--campaign", metavar="DIR",
                        help="write a synthetic validation campaign (eight files and campaign.toml) in DIR "
                             "and print the toml's path; takes --friction (default 0.12), --drag-torque, "
                             "--seed (default 0), --seconds (default 12), --rate, --scene, no other option")
    p.add_argument("--format", choices=SYNTHETIC_FORMATS, default="csv",
                   help="csv (default), lvm, tdms, mat (MATLAB v5), parquet, mdf (ASAM MDF 4, asammdf)")
    p.add_argument("--decimal", choices=(".", ","), default=None,
                   help="decimal mark of csv (',': fields apart by ';'; default '.') and lvm (default ',')")
    p.add_argument("--scene", default="rig", metavar="NAME|FILE",
                   help="the joint: a named scene or a scene TOML file (default rig)")
    p.add_argument("--angle", type=_synthetic_angle, default=None,
                   help="shaft angle [deg] (default: the scene's)")
    speed = p.add_mutually_exclusive_group()
    speed.add_argument("--speed", type=arguments.number("rad/s", positive=True), default=6.0,
                       help="mean input speed [rad/s] (default 6)")
    speed.add_argument("--rpm", type=arguments.number("rpm", positive=True), help="mean input speed [rpm]")
    load = p.add_mutually_exclusive_group()
    load.add_argument("--input-torque", type=arguments.number("N m", positive=True), default=0.2,
                      help="mean input torque [N m] the brake is set for (default 0.2, the paper's)")
    load.add_argument("--load", type=arguments.number("N m", positive=True),
                      help="constant brake torque on the output shaft [N m]")
    p.add_argument("--friction", type=arguments.number("-", non_negative=True),
                   help="friction coefficient of every pair (default: the scene's)")
    p.add_argument("--rate", type=arguments.number("Hz", positive=True), default=1000.0,
                   help="sample rate [Hz] (default 1000)")
    length = p.add_mutually_exclusive_group()
    length.add_argument("--revolutions", type=arguments.number("rev", positive=True), default=5.0,
                        help="input revolutions driven (default 5; the file spans 0.25 more)")
    length.add_argument("--seconds", type=arguments.number("s", positive=True),
                        help="length of the file [s] (instead of --revolutions)")
    p.add_argument("--noise", type=arguments.number("N m", non_negative=True), default=0.005,
                   help="torque noise standard deviation [N m] (default 0.005)")
    p.add_argument("--speed-channel", choices=("pulses", "rpm"), default="pulses")
    p.add_argument("--torque-out-sign", type=int, choices=(1, -1), default=1,
                   help="-1: the output torque recorded negative (read it with --sign torque_out=-1)")
    p.add_argument("--drag-torque", type=arguments.number("N m", non_negative=True), default=0.0,
                   help="constant drag between the joint and the output transducer [N m], a load the "
                        "output transducer does not see (default 0)")
    transducer_options(p)
    p.add_argument("--sensitivity", type=arguments.number("V/(N m)", positive=True), default=0.1,
                   help="torque output of the transducers [V/(N m)] (default 0.1, paper)")
    p.add_argument("--pulses-per-rev", type=arguments.count("--pulses-per-rev"), default=60,
                   help="speed pulses per revolution (default 60, paper)")
    p.add_argument("--seed", type=arguments.count("--seed", minimum=0), default=None,
                   help="seed of the drawn transducer errors and noise (default 1; campaign 0)")
    p.add_argument("--perfect", action="store_true", help="no accuracy-class offsets or drift")
    p.add_argument("--json", action="store_true", help="print the settings used as JSON")


def _synthetic_angle(text: str) -> float:
    """``--angle`` of ``synthetic``: a shaft angle in [0, 90) deg (no ``auto``)."""
    value = shaft_angle(text)
    if value == "auto":
        raise argparse.ArgumentTypeError("a synthetic file needs a shaft angle in [0, 90) deg, got 'auto'")
    return value
