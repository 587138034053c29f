"""``cardan rig campaign CAMPAIGN.toml --out DIR``: calibrate, validate, report (the only campaign module
that prints). Exit status: 0 the campaign ran (resolvable model errors are findings, see ``--strict``);
1 with ``--strict`` and a resolvable model error; 2 bad input (one line); 3 a recording or the
calibration failed; 130/143 interrupted (the journal keeps every model run: rerun to resume).
"""

from __future__ import annotations

import argparse
import json
import signal
import sys
from pathlib import Path
from typing import Any

from cardan_exudyn.arguments import EXIT_BAD_INPUT, EXIT_FAILED, EXIT_OK, BadInput, count, out_folder
from cardan_exudyn.report.format import number

__all__ = ["EXIT_RESOLVABLE", "add_options", "cmd_campaign", "CampaignInterrupted"]

EXIT_RESOLVABLE = 1
"""Exit status with ``--strict`` when a validation recording's model error is resolvable."""


class CampaignInterrupted(KeyboardInterrupt):
    """Ctrl-C or SIGTERM stopped the campaign; the message says where the journal is."""

    def __init__(self, message: str, signum: int = signal.SIGINT) -> None:
        super().__init__(message)
        self.signum = signum


def add_options(p: argparse.ArgumentParser) -> None:
    """The options of ``cardan rig campaign``."""
    p.add_argument("campaign", metavar="CAMPAIGN.toml", help="the campaign file (docs/rigdata.md)")
    p.add_argument("--out", required=True, metavar="DIR",
                   help="folder of the report and of the journal of model runs (rerun to resume)")
    p.add_argument("--json", action="store_true", help="print results.json instead of the table")
    p.add_argument("--workers", type=count("--workers"), default=None, metavar="N",
                   help="processes for the model runs (default: the cores available)")
    p.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help="run on a Dask cluster (tcp://host:port) instead of local processes")
    p.add_argument("--restart", action="store_true",
                   help="forget the journal's model runs and run every model again")
    p.add_argument("--strict", action="store_true",
                   help=f"exit {EXIT_RESOLVABLE} when a validation recording's model error is resolvable")


class _Progress:
    """Stage lines on stderr, nothing with ``--json``. Recordings measured and model-run counts overwrite
    one line on a terminal and are left out elsewhere, so that a recording found unreadable while
    measuring is still the one line of a bad input.
    """

    def __init__(self, quiet: bool) -> None:
        self.quiet = quiet
        self.tty = sys.stderr.isatty()
        self.open = False

    def __call__(self, line: str) -> None:
        if self.quiet:
            return
        if line.startswith(("model runs", "measur")):
            if self.tty:
                print(f"\r\033[Kcardan rig campaign: {line}", end="", file=sys.stderr, flush=True)
                self.open = True
            return
        self.close()
        print(f"cardan rig campaign: {line}", file=sys.stderr, flush=True)

    def close(self) -> None:
        """End the line being overwritten, if any."""
        if self.open:
            print(file=sys.stderr, flush=True)
            self.open = False


def _print_table(s: dict[str, Any]) -> None:
    """The calibration and one line per recording."""
    for p in s["parameters"]:
        u = p["standard_uncertainty"]
        text = "not identifiable" if p["identifiable"] is False else f"+- {number(u, '#.2g')}"
        if not p["calibrated"]:
            text = "(not calibrated: the initial value)"
        print(f"parameter {p['name']} = {number(p['value'], '.4g')} {text}")
    cal = s["calibration"]
    if cal is not None:
        verdict = {True: "REJECTED: the calibration recordings reject the model", False: "not rejected",
                   None: "no degrees of freedom"}[cal["rejected"]]
        print(f"calibration: chi-square {cal['chi_square']:.3g} on {cal['dof']} dof, "
              f"p = {number(cal['p_value'], '.3g')}: {verdict}")
    if s["calibration_error"]:
        print(f"calibration failed: {s['calibration_error']}")
    for r in s["recordings"]:
        print(_line(r))


def _line(r: dict[str, Any]) -> str:
    """One recording: use, S, D, E and its interval, verdict."""
    head = f"{r['label']:<16} {r['use']:<11}"
    if r["status"] != "ok":
        return f"{head} {r['status']}: {r['reason']}"
    low, high = r["model_error_interval"]
    verdict = "calibration" if r["use"] == "calibration" else (
        "RESOLVABLE model error" if r["resolvable"] else "not resolvable")
    return (f"{head} S {r['simulated']:.5f} D {r['measured']:.5f} E {r['comparison_error']:+.5f} "
            f"in [{low:+.5f}, {high:+.5f}] (k u_val {r['k'] * r['u_val']:#.2g}): {verdict}")


def _run(args: argparse.Namespace, spec: Any) -> Any:
    """The campaign of ``spec`` into ``--out``: an unreachable scheduler is bad input; an interruption
    says where the journal is."""
    from cardan_exudyn.sweep.checks import SweepError
    from rigdata.campaign.journal import JOURNAL_FILE
    from rigdata.campaign.run import campaign

    journal = Path(args.out) / JOURNAL_FILE
    if args.restart and journal.is_file():
        journal.unlink()
    progress = _Progress(args.json)
    try:
        return campaign(spec, args.out, workers=args.workers, scheduler=args.scheduler, progress=progress)
    except SweepError as exc:  # the Dask scheduler cannot be reached
        raise BadInput(str(exc)) from None
    except KeyboardInterrupt as exc:
        signum = getattr(exc, "signum", signal.SIGINT)
        raise CampaignInterrupted(f"every finished model run is kept in {journal}; rerun the same command "
                                  "to resume", signum) from None
    finally:
        progress.close()


def cmd_campaign(args: argparse.Namespace) -> int:
    """Run the campaign, write the report into ``--out``; see the module's exit statuses."""
    from rigdata.campaign.spec import CampaignError, load_campaign

    out_folder(args.out, replace=False)
    try:
        spec = load_campaign(args.campaign)
    except CampaignError as exc:
        print(f"cardan rig campaign: error: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    result = _run(args, spec)
    from rigdata.campaign.report import write_report  # matplotlib: loaded only once there is a result

    s = result.as_dict()
    write_report(result, args.out)
    if args.json:
        print(json.dumps(s, indent=2))
    else:
        _print_table(s)
        print(f"wrote {args.out}/report.html", file=sys.stderr)
    if result.failed or result.calibration_error:
        return EXIT_FAILED
    return EXIT_RESOLVABLE if args.strict and result.resolvable else EXIT_OK
