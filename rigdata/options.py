"""Options and their conversion shared by the ``cardan rig`` commands: settings objects whose refusal is
bad input, ``CHANNEL=VALUE`` pairs, the shaft angle, the transducers.
"""

from __future__ import annotations

import argparse
from typing import Any

import rigdata
from cardan_exudyn import arguments
from cardan_exudyn.arguments import BadInput

__all__ = ["settings", "pairs", "shaft_angle", "transducers", "transducer_options"]


def settings(cls: type, **kwargs: Any) -> Any:
    """A settings object (Conditioning, Transducer, RigSettings); a value it refuses is bad input."""
    try:
        return cls(**kwargs)
    except ValueError as exc:
        raise BadInput(str(exc)) from None


def pairs(values: list[str] | None, option: str) -> dict[str, str]:
    """``CHANNEL=VALUE`` items of a repeatable option as a dict; :class:`BadInput` otherwise."""
    out = {}
    for item in values or []:
        key, sep, value = item.partition("=")
        if not sep or not key.strip() or not value.strip():
            raise BadInput(f"{option} expects CHANNEL=VALUE, got {item!r}")
        out[key.strip()] = value.strip()
    return out


def shaft_angle(text: str) -> float | str:
    """``--angle``: a shaft angle in [0, 90) deg, or ``auto`` (the recording's own)."""
    if text.strip().lower() == "auto":
        return "auto"
    value = arguments.number("deg", non_negative=True)(text)
    if value >= 90.0:
        raise argparse.ArgumentTypeError(f"must be below 90 deg (a joint at 90 deg transmits no motion), "
                                         f"got {text!r}")
    return value


def transducers(args: argparse.Namespace) -> tuple[rigdata.Transducer, rigdata.Transducer]:
    """Both transducers from the options (the rig's two are alike)."""
    t = settings(rigdata.Transducer, full_scale=args.full_scale, sensitivity=args.sensitivity,
                  pulses_per_rev=args.pulses_per_rev, accuracy_class=args.accuracy_class / 100.0,
                  zero_drift=args.zero_drift, speed_accuracy=args.speed_accuracy / 100.0)
    return t, t


def transducer_options(p: argparse.ArgumentParser) -> None:
    """Full scale, accuracy class, zero drift and speed accuracy of the transducers."""
    p.add_argument("--full-scale", type=arguments.number("N m", positive=True), default=100.0,
                   help="transducer full scale [N m] (default 100, paper)")
    p.add_argument("--accuracy-class", type=arguments.number("%", non_negative=True, maximum=100.0),
                   default=0.1,
                   help="transducer accuracy class [%% of full scale] (default 0.1, assumed)")
    p.add_argument("--zero-drift", type=arguments.number("N m", non_negative=True), default=0.01,
                   help="limit of the zero drift over the record [N m] (default 0.01, assumed)")
    p.add_argument("--speed-accuracy", type=arguments.number("%", non_negative=True, maximum=100.0),
                   default=0.1,
                   help="speed channel gain error limit [%% of reading] (default 0.1, assumed; not "
                        "used for pulse counts)")
