"""``python tests/benchmarks campaign-truth | campaign-coverage | campaign-groups | campaign-sampling``:
the campaign studies (:mod:`.studies`), printed and written as JSON into ``--out``."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from cardan_exudyn.arguments import EXIT_OK
from cardan_exudyn.jsonable import to_jsonable

__all__ = ["register"]

HELP = {
    "campaign-truth": "the default eight-recording campaign (12 s, both engines), without and with a drag "
                      "torque the model lacks: estimate, chi-square test, verdicts, wall time by stage",
    "campaign-coverage": "the consistent campaign over many noise seeds: interval coverage",
    "campaign-groups": "spider and frame friction as two parameters on quasi-static recordings",
    "campaign-sampling": "u_input by sensitivity coefficients against sampled model runs",
}


def register(subparsers: argparse._SubParsersAction, name: str) -> None:
    """Add campaign study ``name``."""
    p = subparsers.add_parser(name, help=HELP[name], description=HELP[name])
    p.add_argument("--out", metavar="DIR", default=f"reports/{name}", help="folder of the files and JSON")
    p.add_argument("--workers", type=int, default=None, help="processes (default: the cores)")
    if name == "campaign-truth":
        p.add_argument("--seconds", type=float, default=12.0, help="length of each recording [s]")
        p.add_argument("--drag", type=float, action="append", help="drag torque [N m] (default 0 and 0.03)")
    if name == "campaign-coverage":
        p.add_argument("--seeds", type=int, default=50)
        p.add_argument("--seconds", type=float, default=4.0)
    p.set_defaults(func=_handler(name))


def _handler(name: str):
    """The study of ``name`` as an argparse handler."""
    def run(args: argparse.Namespace) -> int:
        from benchmarks.campaign import studies

        out = Path(args.out)
        out.mkdir(parents=True, exist_ok=True)
        if name == "campaign-truth":
            summary = [studies.truth_campaign(out / f"drag-{d:g}", d, args.seconds, args.workers)
                       for d in (args.drag or [0.0, 0.03])]
        elif name == "campaign-coverage":
            summary = studies.coverage(out, args.seeds, args.seconds, args.workers)
        elif name == "campaign-sampling":
            summary = studies.sampling_check(out, workers=args.workers)
        else:
            summary = studies.tied_groups(out, workers=args.workers)
        text = json.dumps(to_jsonable(summary), indent=1)
        (out / "summary.json").write_text(text)
        print(text)
        return EXIT_OK

    return run
