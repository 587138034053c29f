"""A sweep's records on disk: ``cases.jsonl``, resume, atomic appends, the results table.

A record is one flat JSON object per finished case (:data:`RECORD_KEYS` plus the case function's
scalar outputs), appended and fsync'ed as the case finishes so that an interrupted sweep resumes.
"""

from __future__ import annotations

import contextlib
import json
import os
from collections.abc import Iterator, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from cardan_exudyn import engines
from cardan_exudyn.interrupts import deferred_signals
from cardan_exudyn.jsonable import to_jsonable
from cardan_exudyn.outputs import atomic_write
from cardan_exudyn.sweep.checks import SweepError
from cardan_exudyn.sweep.plan import Case, Plan, plan_difference
from reference.results.summary import Status, Summary
from reference.scene.scene import Scene

__all__ = ["PLAN_FILE", "CASES_FILE", "RESULTS_FILE", "SUMMARY_FILE", "SWEEP_FILES", "RECORD_KEYS",
           "RESERVED_OUTPUTS", "read_records", "RecordWriter", "existing_records", "locked",
           "write_text", "interrupted_record", "error_record", "results_table", "statistics",
           "scalar_summary", "summary_outputs"]

PLAN_FILE = "plan.json"
CASES_FILE = "cases.jsonl"
RESULTS_FILE = "results.csv"
SUMMARY_FILE = "sweep.json"
SWEEP_FILES = (PLAN_FILE, CASES_FILE, RESULTS_FILE, SUMMARY_FILE)
"""The files a sweep writes into its folder (the only ones ``--restart`` deletes)."""
RECORD_KEYS = ("id", "engine", "overrides", "status", "reason", "error_type", "error", "case_wall_s")
"""Keys of a record that the runner sets."""
RESERVED_OUTPUTS = frozenset({"id", "overrides", "error_type", "error", "case_wall_s", "traceback"})
"""Keys a case function must not return."""
ERROR = "error"
"""The status of a case whose function raised or whose process died."""


def write_text(path: Path, text: str) -> None:
    """Write ``text`` (UTF-8) to ``path`` atomically (temporary sibling, fsync, rename)."""
    atomic_write(path, lambda f: f.write(text.encode("utf-8")))


def read_records(path: str | os.PathLike, *, truncate: bool = False) -> dict[str, dict[str, Any]]:
    """Records of ``cases.jsonl`` by case id (the last record of an id wins).

    Parameters
    ----------
    path : path
        The ``cases.jsonl`` file; a missing file has no records.
    truncate : bool
        Cut off an incomplete last line (a kill during the write) so the next record starts on its
        own line; the line is ignored either way.

    Returns
    -------
    dict of str to dict
        Case id -> record.

    Raises
    ------
    SweepError
        A complete line that is not a JSON record with a string ``id``.
    """
    path = Path(path)
    if not path.exists():
        return {}
    data = path.read_bytes()
    end = data.rfind(b"\n") + 1
    records = {}
    for number, line in enumerate(data[:end].splitlines(), start=1):
        if not line.strip():
            continue
        try:
            record = json.loads(line)
        except ValueError as exc:
            raise SweepError(f"{path}:{number} is not a JSON record ({exc}); delete that line or "
                             "use --restart") from None
        if not isinstance(record, dict) or not isinstance(record.get("id"), str):
            raise SweepError(f"{path}:{number} is not a case record (no string `id`)")
        records[record["id"]] = record
    if truncate and end < len(data):
        with open(path, "r+b") as f:
            f.truncate(end)
            os.fsync(f.fileno())
    return records


class RecordWriter:
    """Appends records to ``cases.jsonl``, one line each, flushed and fsync'ed."""

    def __init__(self, path: Path) -> None:
        self._file = open(path, "ab")

    def write(self, record: Mapping[str, Any]) -> None:
        """Append one record; on disk when this returns (Ctrl-C and SIGTERM wait for it)."""
        line = json.dumps(to_jsonable(record), allow_nan=False, separators=(",", ":")) + "\n"
        with deferred_signals():
            self._file.write(line.encode("utf-8"))
            self._file.flush()
            os.fsync(self._file.fileno())

    def write_many(self, records: Sequence[Mapping[str, Any]]) -> None:
        """Append several records (a batch's) with one fsync; on disk together when this returns."""
        text = "".join(json.dumps(to_jsonable(r), allow_nan=False, separators=(",", ":")) + "\n"
                       for r in records)
        with deferred_signals():
            self._file.write(text.encode("utf-8"))
            self._file.flush()
            os.fsync(self._file.fileno())

    def close(self) -> None:
        """Close the file."""
        self._file.close()


def existing_records(out: Path, plan: Plan) -> dict[str, dict[str, Any]]:
    """Case id -> record already in folder ``out`` for ``plan`` (empty for a new sweep); SweepError,
    suggesting ``--restart``, when ``out`` holds another sweep.
    """
    plan_path = out / PLAN_FILE
    cases_path = out / CASES_FILE
    if not plan_path.exists():
        if cases_path.exists():
            raise SweepError(f"{out} has {CASES_FILE} but no {PLAN_FILE}; use --restart or another --out")
        return {}
    try:
        stored = json.loads(plan_path.read_text(encoding="utf-8"))
    except ValueError as exc:
        raise SweepError(f"{plan_path} is not valid JSON ({exc}); use --restart") from None
    problem = plan_difference(stored, plan.to_dict())
    if problem:
        raise SweepError(f"{out} holds a different sweep ({problem}); rerun with --restart to discard "
                         "its records, or use another --out")
    records = read_records(cases_path)
    unknown = sorted(set(records) - {c.id for c in plan.cases})
    if unknown:
        raise SweepError(f"{cases_path} has records of cases not in the plan: {unknown[:5]}")
    return records


@contextlib.contextmanager
def locked(out: Path) -> Iterator[None]:
    """Hold an exclusive lock on ``out`` so that two drivers never append to one sweep."""
    try:
        import fcntl
    except ImportError:  # Windows: no advisory lock
        yield
        return
    with open(out / ".lock", "w") as f:
        try:
            fcntl.flock(f, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            raise SweepError(f"another sweep is running in {out}") from None
        yield


_INTERRUPTED_REASON = "Error in Python USER FUNCTION"
"""Exudyn's reason for a Python exception escaping a user function."""


def interrupted_record(record: Mapping[str, Any]) -> bool:
    """Whether a stored record is a case stopped by Ctrl-C (``integration_failure`` with Exudyn's
    user-function failure as reason; the friction update records its own exceptions as ``error``);
    such a case runs again on resume.
    """
    return (record.get("status") == Status.INTEGRATION_FAILURE
            and _INTERRUPTED_REASON in str(record.get("reason") or ""))


def error_record(case: Case, error_type: str, error: str) -> dict[str, Any]:
    """The :data:`ERROR` record of ``case`` whose worker died: ``error_type`` (``"WorkerCrash"``,
    ``"KilledWorker"``) and ``error`` in words.
    """
    return {**case.to_dict(), "status": ERROR, "reason": f"{error_type}: {error}",
            "error_type": error_type, "error": error, "case_wall_s": None}


def results_table(plan: Plan, records: Mapping[str, Mapping[str, Any]]):
    """One row per recorded case in plan order: id, engine, parameters, status, outputs.

    Non-scalar parameters are JSON text; an output named like a parameter becomes ``result.<name>``.

    Parameters
    ----------
    plan : Plan
    records : mapping of str to mapping
        Case id -> record.

    Returns
    -------
    pandas.DataFrame
        The content of ``results.csv``.
    """
    import pandas as pd  # pandas takes about 0.3 s to import: only the driver's last step needs it

    params = plan.parameters
    rows = [_row(case, record, params) for case in plan.cases
            if (record := records.get(case.id)) is not None]
    head = ["id", "engine", *params, *RECORD_KEYS[3:]]
    table = pd.DataFrame(rows)
    for column in head:
        if column not in table:
            table[column] = None
    return table[head + [c for c in table.columns if c not in head]]


def _row(case: Case, record: Mapping[str, Any], params: Sequence[str]) -> dict[str, Any]:
    """One row of the results table: id, engine, the case's parameters, the record's outputs."""
    row: dict[str, Any] = {"id": case.id, "engine": record.get("engine", case.engine)}
    row.update({p: _cell(case.overrides.get(p)) for p in params})
    for key, value in record.items():
        if key not in ("id", "engine", "overrides", "traceback"):
            row[f"result.{key}" if key in params else key] = _cell(value)
    return row


def _cell(value: Any) -> Any:
    """A value for a CSV cell: lists and tables as JSON text."""
    return json.dumps(to_jsonable(value)) if isinstance(value, (list, tuple, dict)) else value


def statistics(table, parameters: Sequence[str] = ()) -> dict[str, dict[str, float]]:
    """Statistics of every numeric output over the cases with status ``ok``.

    Parameters
    ----------
    table : pandas.DataFrame
        A :func:`results_table`.
    parameters : sequence of str
        Swept paths (not outputs).

    Returns
    -------
    dict
        Output -> n, mean, std, min, p05, p50, p95, max (the output's unit); ``case_wall_s`` [s]
        over every recorded case: n, mean, min, p50, max.
    """
    import pandas as pd  # as in results_table: the driver's last step only

    ok = table[table["status"] == Status.OK]
    skip = {"id", "engine", *parameters, *RECORD_KEYS}
    stats = {}
    for column in ok.columns:
        if column in skip or column == "case_wall_s":
            continue
        values = pd.to_numeric(ok[column], errors="coerce") if ok[column].dtype != bool else None
        if values is None or values.notna().sum() == 0 or ok[column].map(_is_text).any():
            continue
        stats[column] = _describe(values.dropna().to_numpy(dtype=float))
    wall = pd.to_numeric(table["case_wall_s"], errors="coerce").dropna().to_numpy(dtype=float)
    if wall.size:
        stats["case_wall_s"] = {"n": int(wall.size), "mean": float(wall.mean()), "min": float(wall.min()),
                                "p50": float(np.median(wall)), "max": float(wall.max())}
    return stats


def _describe(x: np.ndarray) -> dict[str, float]:
    """n, mean, std, min, p05, p50, p95, max of ``x`` (one value: std 0)."""
    q05, q50, q95 = np.quantile(x, [0.05, 0.5, 0.95])
    return {"n": int(x.size), "mean": float(x.mean()),
            "std": float(x.std(ddof=1)) if x.size > 1 else 0.0, "min": float(x.min()),
            "p05": float(q05), "p50": float(q50), "p95": float(q95), "max": float(x.max())}


def _is_text(value: Any) -> bool:
    """Strings and booleans: outputs that have no statistics."""
    return isinstance(value, (str, bool))


def scalar_summary(summary: Summary | Mapping[str, Any]) -> dict[str, Any]:
    """The scalar values of an engine summary: top-level numbers, strings, booleans and None, those of
    nested tables as ``table.key``, ``warnings`` joined by "; "; lists and the scene dropped.
    """
    out: dict[str, Any] = {}
    if isinstance(summary, Summary):
        summary = summary.to_dict()
    for key, value in summary.items():
        if key in ("scene", "schema_version"):
            continue
        if isinstance(value, Mapping):
            out.update({f"{key}.{k}": v for k, v in value.items() if _is_scalar(v)})
        elif key == "warnings":
            out[key] = "; ".join(value)
        elif _is_scalar(value):
            out[key] = value
    return to_jsonable(out)


def _is_scalar(value: Any) -> bool:
    """None, a string, a boolean or a number: a value :func:`scalar_summary` keeps."""
    return value is None or isinstance(value, (str, bool, int, float, np.generic))


def summary_outputs(scene: Scene, engine: str) -> dict[str, Any]:
    """Default case function: :func:`scalar_summary` of running ``scene`` with ``engine``."""
    return scalar_summary(engines.run(scene, engine).summary)
