"""A cell of ``cardan stress``'s map classified from its measurements alone (:func:`classify`).

``converged``: Exudyn ok, ratio error <= ``SAFETY * K(beta) h^2 + RATIO_FLOOR``
(:mod:`cardan_exudyn.model.stepsize`), ``|eta - eta_ref| <= SAFETY * 2^p / (2^p - 1)
|eta_h - eta_h/2| + EFFICIENCY_FLOOR`` (step-halving estimate, order ``p``), eta in [0, 1], pair
constraints within ``CONSTRAINT_LIMIT``. ``drift``: ok but a check fails. ``self_locking``:
Exudyn's friction fixed point does not converge. ``integration_failure``: Newton or integrator
failed, or ``unphysical``. ``error``: the harness raised. The reference self-locks when its loop
gain reaches 1 at some instant; disagreements are categorised (``docs/stress.md``).
"""

from __future__ import annotations

import math
from typing import Any

from cardan_exudyn.report.format import number
from reference.results.summary import Status

__all__ = ["SAFETY", "RATIO_FLOOR", "EFFICIENCY_FLOOR", "CONSTRAINT_LIMIT", "ORDER", "CLASSES",
           "EXUDYN_FAILURES", "MEASURED", "as_float", "efficiency_promise", "broken_promises",
           "cell_class", "classify", "measured"]


SAFETY = 3.0
"""Factor on the promised error."""
RATIO_FLOOR = 1e-8
"""Speed-ratio error the Newton tolerance leaves at zero shaft angle [-]."""
EFFICIENCY_FLOOR = 1e-4
"""Efficiency difference below which the engines count as equal [-]."""
CONSTRAINT_LIMIT = 1e-6
"""[m] and [rad]: pair constraints of an index-3 solve hold far better."""
ORDER = {"converged": 2, "extrapolated": 2, "lagged": 1}
"""Order of the mean efficiency in the step, per friction coupling."""
CLASSES = ("converged", "drift", "self_locking", "integration_failure", "error")
# statuses of a numerical failure; ``unphysical``: means no run can have (an efficiency outside
# [0, 1] from too coarse a step), caught by the engine instead of reported as ``drift``
EXUDYN_FAILURES = ("integration_failure", "diverged", "incomplete", "no_whole_revolution",
                   "loop_does_not_close", "unphysical")


def as_float(value: Any) -> float:
    """``value`` as a float; NaN for None or anything else that is not a number."""
    try:
        return float(value)
    except (TypeError, ValueError):
        return float("nan")


def efficiency_promise(record: dict[str, Any]) -> float:
    """``SAFETY * 2^p / (2^p - 1) |eta_h - eta_h/2| + EFFICIENCY_FLOOR`` with the order ``p`` of
    the record's ``coupling`` (NaN without a halved run)."""
    a = as_float(record.get("exu_efficiency"))
    b = as_float(record.get("exu_efficiency_half"))
    if record.get("half_status") != Status.OK or not (math.isfinite(a) and math.isfinite(b)):
        return float("nan")
    p = ORDER[record.get("coupling", "converged")]
    return SAFETY * 2.0**p / (2.0**p - 1.0) * abs(a - b) + EFFICIENCY_FLOOR


def broken_promises(record: dict[str, Any]) -> list[str]:
    """The checks an ok Exudyn run fails (empty: converged): speed ratio and efficiency within their
    promises, efficiency in [0, 1], constraints.
    """
    reasons = []
    ratio_err = as_float(record.get("ratio_error"))
    promise = as_float(record.get("ratio_promise"))
    if not ratio_err <= promise:  # written so that NaN fails
        reasons.append(f"speed-ratio error {number(ratio_err, '.2g')} > promised {number(promise, '.2g')}")
    eta = as_float(record.get("exu_efficiency"))
    eta_ref = as_float(record.get("ref_efficiency"))
    if not 0.0 <= eta <= 1.0:
        reasons.append(f"mean efficiency {number(eta, '.4g')} outside [0, 1]")
    for key, unit in (("constraint_violation_m", "m"), ("constraint_violation_rad", "rad")):
        v = as_float(record.get(key))
        if not v <= CONSTRAINT_LIMIT:
            reasons.append(f"constraint violation {number(v, '.2g')} {unit} > {CONSTRAINT_LIMIT:g}")
    if record.get("ref_status") == Status.OK:
        promise = efficiency_promise(record)
        if not math.isfinite(promise):  # frictionless, or the halved run failed
            promise = EFFICIENCY_FLOOR
        if not abs(eta - eta_ref) <= promise:
            reasons.append(f"efficiency {number(eta, '.4f')} vs reference {number(eta_ref, '.4f')}: "
                           f"|error| {number(abs(eta - eta_ref), '.2g')} > promised {promise:.2g}")
    return reasons


def cell_class(record: dict[str, Any]) -> tuple[str, list[str]]:
    """Exudyn's class of the cell (:data:`CLASSES` but ``error``) and, for ``drift``, why."""
    exu = record.get("exu_status")
    if exu == Status.OK:
        reasons = broken_promises(record)
        locks = record.get("ref_status") == Status.SELF_LOCKING
        return ("drift" if reasons or locks else "converged"), reasons
    if exu == Status.SELF_LOCKING:
        return "self_locking", []
    return "integration_failure", ([] if exu in EXUDYN_FAILURES else [f"unexpected status {exu!r}"])


def _verdict(cls: str, reference: str, agrees: bool, category: str, explanation: str = "") -> dict[str, Any]:
    """A cell's classification as :func:`classify` returns it."""
    return {"cell_class": cls, "reference": reference, "agrees": agrees, "category": category,
            "explanation": explanation}


def _where_reference_runs(record: dict[str, Any], cls: str, reasons: list[str]) -> dict[str, Any]:
    """The verdict where the reference's friction fixed point has a solution throughout."""
    exu_reason = str(record.get("exu_reason") or "")[:120]
    if cls == "converged":
        return _verdict(cls, "ok", True, "agree: ok")
    if cls == "drift":
        return _verdict(cls, "ok", False, "wrong answer with status ok", "; ".join(reasons))
    if cls == Status.SELF_LOCKING:
        return _verdict(cls, "ok", False, "Exudyn locks, the reference does not",
                        f"reference loop gain max {number(as_float(record.get('ref_loop_gain_max')), '.3g')}"
                        f" < 1; Exudyn: {exu_reason}")
    return _verdict(cls, "ok", False, "numerical failure in a physically valid cell",
                    f"Exudyn {record.get('exu_status')}: {exu_reason}")


def _where_reference_locks(record: dict[str, Any], cls: str, reasons: list[str]) -> dict[str, Any]:
    """The verdict where the reference's friction fixed point has no solution: the joint locks."""
    if cls == Status.SELF_LOCKING:
        return _verdict(cls, "self_locking", True, "agree: self-locking")
    if cls == Status.INTEGRATION_FAILURE:
        return _verdict(cls, "self_locking", True, "agree: fails where the joint locks",
                        f"Exudyn {record.get('exu_status')} instead of a self-locking verdict: "
                        f"{str(record.get('exu_reason') or '')[:120]}")
    gain = as_float(record.get("exu_loop_gain_max"))
    explanation = (f"reference self-locks ({str(record.get('ref_reason'))[:80]}); Exudyn ok with "
                   f"efficiency {number(as_float(record.get('exu_efficiency')), '.4g')}"
                   + (f", loop gain estimate max {gain:.3g}" if math.isfinite(gain) else "")
                   + (f"; {'; '.join(reasons)}" if reasons else ""))
    return _verdict(cls, "self_locking", False, "runs on through a physical self-lock", explanation)


def classify(record: dict[str, Any]) -> dict[str, Any]:
    """Class, agreement with the reference, category and a one-line explanation of a cell from its
    ``record`` (:func:`measure_cell`'s, or a harness error).
    """
    if record.get("status", "ok") != Status.OK:  # the case function raised
        return _verdict("error", "unknown", False, "harness error", str(record.get("reason"))[:200])
    cls, reasons = cell_class(record)
    ref = record.get("ref_status")
    if ref == Status.OK:
        return _where_reference_runs(record, cls, reasons)
    if ref == Status.SELF_LOCKING:
        return _where_reference_locks(record, cls, reasons)
    return _verdict(cls, f"failed ({ref})", False, "reference failed",
                    f"reference {ref}: {str(record.get('ref_reason'))[:120]}")


MEASURED = ("ref_status", "ref_efficiency", "ref_loop_gain_max", "exu_status", "exu_efficiency",
            "exu_efficiency_half", "half_status", "exu_loop_gain_max", "ratio_error",
            "ratio_promise", "constraint_violation_m", "constraint_violation_rad", "exu_steps",
            "exu_newton_iterations", "exu_wall_s", "case_wall_s", "exu_reason", "ref_reason")


def measured(record: dict[str, Any]) -> dict[str, Any]:
    """The record's measurements (:data:`MEASURED`), the efficiency promise and error."""
    out = {k: record.get(k) for k in MEASURED}
    out["efficiency_promise"] = efficiency_promise(record)
    eta = as_float(record.get("exu_efficiency"))
    ref = as_float(record.get("ref_efficiency"))
    out["efficiency_error"] = abs(eta - ref) if math.isfinite(eta) and math.isfinite(ref) else None
    return out
