"""Property-based tests (hypothesis): what must hold for every valid scene, in both engines.

Cells (:func:`cells`) are drawn from the paper's joint (plain or calibrated parameter set) over the
valid region: shaft angle 0-80 deg, input speed 1-3000 rpm either way, a load resisting the motion
0-10 N m, friction coefficients 0-1 of the spider pairs (f1) and of the frame pairs (f2), every
coupling scheme, gravity on or off, mounting errors a1..a3 within +-1 mm and alpha1..3 within
+-0.1 deg (or none), one revolution; for Exudyn every node type and the step for a speed-ratio
error of ``ACCURACY = 1e-3`` (100 to 2,824 steps per revolution), given as ``numerics.dt`` (the
automatic step now serves the mean efficiency's accuracy; issue 18). Much of the region
self-locks (friction 1, large angles): there the property is the status contract.

Properties
----------
Status contract (every cell)
    The status is one of the engine's statuses (:data:`STATUSES`, collected from the code);
    ``reason`` is a string, empty for ``ok``, saying why otherwise; a run that is not ``ok`` presents
    no efficiency: ``mean_efficiency``, ``mean_instantaneous_efficiency``, ``work_ratio`` absent or
    None.
Status ``ok``
    Every table column (reactions, friction, relative motion, powers, energies, the reference's
    extra columns) and every number of the summary is finite. The one exception in the table is
    a quotient 0/0, which is NaN: ``efficiency`` exactly where the input power is exactly zero.
    A mean that is undefined is None with a warning (issue 18): ``mean_efficiency`` and
    ``work_ratio`` when no work is transmitted or lost, the time average of eq. (18) where the
    source power changes sign or the average leaves [0, 1]. The ``efficiency`` column is eq. (18),
    friction never generates power (reference: per sample exactly; Exudyn converged: to the
    fixed-point tolerance), and without friction the mean efficiency is exactly 1 and the column
    exactly 1 where defined.
Energy balance
    Over the whole revolutions ``W_in = W_out + W_loss + dE`` (``tests/test_energy.py``'s
    ``balance_residual``), to :func:`balance_tolerance`. ``uncoupled`` friction leaves the dynamics
    frictionless and estimates the loss on the side: there ``W_in = W_out + dE``.
Mean efficiency in [0, 1]
    With status ok it is in [0, 1] or None (issue 18: a value outside is status ``unphysical``).
    With a resisting load ``W_out >= 0`` and ``W_loss >= 0``; with no load no shaft takes net work
    (``power_flow`` ``none``) and the efficiency is 0 (None without friction): it used to be the
    quotient of the loss and an input work of the size of the balance error (Exudyn gave 0.546
    where the reference gave 0 at 51 deg, no load, f = 0.004, 100 steps).
Eq. (18) in [0, 1] where power flows one way
    Eq. (18) is not bounded in general: it has poles where the input power changes sign (inertia
    or gravity drive the input over part of a revolution; the reference's 45 deg paper case has a
    time average of -0.41 with status ok; README and the reproduce report say so). The
    quasi-static cells (gravity off, <= 60 rpm, >= 0.2 N m, <= 45 deg; inertial power below 1 % of
    the output power, checked, 0.2 % measured) have one-way power flow: there the column and its
    time average are in [0, 1].
Engines agree
    Where the reference runs ok with friction loop gain <= 0.5 (half-way to self-locking; up to
    50 deg, f <= 0.5, >= 0.2 N m), Exudyn at its default step (``numerics.accuracy`` 1e-5) runs ok
    too, and its mean efficiency is within :func:`efficiency_tolerance` of the reference's.
Status at the locking boundary
    44-52 deg with the paper's friction, reference tables of 3-40 samples per revolution: locking
    found only at quadrature nodes between samples keeps the status contract.

Tolerances and their reasons
----------------------------
``h = omega dt`` is the input-angle step, ``K(beta) = 0.19 tan^2 / cos^2`` the step-size model's
coefficient (:mod:`cardan_exudyn.model.stepsize`), ``S`` the energy scale of the run:
``int(|P_in| + |P_out| + |P_loss|) dt`` plus the largest kinetic energy (work integrals and the
integrator's energy err relative to what flows and what is stored; the kinetic energy matters
where unbalanced inertia forces do no net work: at 3.9 deg, 2601 rpm with gravity the power flow
alone under-states the scale 40 times).

- Energy balance, Exudyn: ``|r| <= C_E (1 + K) h^2 S``, ``C_E = 0.2``. ``|r| / ((1 + K) h^2 S)``
  measured: at most 0.053 on 120 scripted random cells, 0.079 over 1,143 ok runs of the slow
  properties, and 0.102 at 30 deg, 14 rpm, f1 = 1, loop gain 0.92 (found by hypothesis; 0.1009 /
  0.1017 / 0.1022 / 0.1024 at 100 / 200 / 400 / 800 steps: second order). ``1 + K`` is the
  model's angle dependence: without it the constant ranges from 4e-4 (8 deg) to 0.9 (80 deg).
  ``C_E`` holds at the speed-ratio steps above; at much finer steps the lagged coupling exceeds
  it (found by hypothesis at the automatic step of issue 18, 5,752 steps per revolution: 42 deg,
  1 rpm, f1 = 0.875, f2 = 0, 1 N m, gravity, lagged: 0.148 / 0.169 / 0.186 / 0.200 / 0.209 /
  0.214 at 200 / 400 / 800 / 1600 / 3200 / 6400 steps, second order with a constant tending to
  about 0.22; converged 0.093 / 0.096 at 400 / 1600). That is why the step is given.
- Energy balance, reference: ``|r| <= 3 quadrature_rtol S`` (3e-9 S; the three work integrals are
  each adaptive Gauss-Legendre to ``quadrature_rtol`` of their scale, the energies exact);
  measured at most 1e-14 S (rounding).
- Without friction: mean efficiency exactly 1 (the loss is exactly zero); the column exactly 1
  where defined; its time average 1 to 1e-12 (trapezoidal average of ones).
- Dissipation, Exudyn converged: ``P_loss >= -2 tol max|friction load| sum(max relative speed)``,
  the fixed-point residual's power.
- Mean efficiency between engines: ``|d eta| <= h^2 (1 + K) (C_1 S + C_2 W_loss) / W_in``, plus
  ``C_lag h W_loss / W_in`` for lagged friction (one step late, first order); an energy-scale
  part as the balance, and a relative error of the loss work (the friction follows reactions
  whose accelerations carry the integration error). Measured: the first part at most 0.10 on 70
  scripted cells, the loss part at most 7 (26.8 deg, f2 = 0.44, 2811 rpm, loop gain 0.45; second
  order from 200 to 3200 steps per revolution), ``C_lag`` at most 0.07; ``C_1 = 0.2``,
  ``C_2 = 14``, ``C_lag = 0.15``. At the default step the slow property measured at most 0.21 of
  this bound (converged, 206 cells) and 0.33 (lagged, 144). Coarser steps are pre-asymptotic for
  frame friction above 30 deg: at 44 deg and 116 steps per revolution (accuracy 1e-3) the loss
  work is 12 % off for f2 = 0.01 (5.8e-3 in efficiency), so the comparison uses the default step.

Default: a few dozen to a hundred derandomized examples per property, no example database (CI
reproduces them), about 20 s; ``-m slow``: the same properties on 300 to 1,500 examples (about
5 minutes). ``PROPERTIES_LOG=file`` appends the measured ratios, to re-measure the constants.
"""

from __future__ import annotations

import functools
import json
import math
import os

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, example, given, settings
from hypothesis import strategies as st
from test_energy import balance_residual

from cardan_exudyn import run as run_engine
from cardan_exudyn.model.options import NODE_TYPES, ExudynOptions
from cardan_exudyn.model.stepsize import choose_step, error_coefficient
from reference.engine.options import ReferenceOptions
from reference.paper.scenes import named_scene
from reference.scene.joint import PAIR_KIND, PAIR_NAMES
from reference.scene.mapping import replace
from reference.scene.settings import COUPLINGS, Numerics
from reference.scene.validation import DEG, RPM

# --------------------------------------------------------------------------- contract

#: Every status an engine returns for a constant-speed scene (collected from the code):
#: ``ok``; ``self_locking`` (no consistent friction: reference per sample or quadrature node,
#: Exudyn's fixed point at the start or in a step, lagged geometric growth);
#: ``integration_failure`` (solver error, or nothing recorded), ``diverged`` (non-finite
#: values), ``incomplete`` (torque drive short of its span), ``no_whole_revolution`` (means
#: impossible), ``loop_does_not_close`` (mounting errors), ``unphysical`` (an efficiency outside
#: [0, 1]). A mean that is undefined is None in an ``ok`` summary, with a warning: the CLI prints
#: "undefined" and JSON writes null (``cardan_exudyn.cli``, ``cardan_exudyn.outputs``).
COMMON_STATUSES = {"ok", "self_locking", "integration_failure", "incomplete", "no_whole_revolution",
                   "loop_does_not_close", "unphysical"}
STATUSES = {"reference": COMMON_STATUSES, "exudyn": COMMON_STATUSES | {"diverged"}}
EFFICIENCY_KEYS = ("mean_efficiency", "mean_instantaneous_efficiency", "work_ratio")

ACCURACY = 1e-3      # speed-ratio error the Exudyn step is chosen for (coarse but valid; given as
                     # numerics.dt: the automatic step now serves the mean efficiency's accuracy)
AGREE_ACCURACY = Numerics().accuracy  # the engines compared at the default step (1e-3 since issue 18;
                                      # the bound below follows the step taken)
C_E = 0.2            # energy balance, Exudyn: |r| <= C_E (1 + K) h^2 S
REF_BALANCE = 3 * ReferenceOptions().quadrature_rtol  # energy balance, reference: |r| <= it S
C_1, C_2, C_LAG = 0.2, 14.0, 0.15  # mean efficiency, Exudyn against the reference
CLEARLY_OK_GAIN = 0.5  # friction loop gain (reference) below which a cell is clearly not locking


# --------------------------------------------------------------------------- cells

def _maybe_zero(hi: float) -> st.SearchStrategy[float]:
    """Exactly 0 (the frictionless / unloaded edge) as a branch of its own, else [0, hi]."""
    return st.integers(0, 3).flatmap(lambda i: st.just(0.0) if i == 0 else st.floats(0.0, hi))


ERRORS = st.fixed_dictionaries({
    **{f"a{k}": st.floats(-1e-3, 1e-3) for k in (1, 2, 3)},       # m
    **{f"alpha{k}": st.floats(-0.1, 0.1) for k in (1, 2, 3)},     # deg
})


def cells(max_angle: float = 80.0, min_rpm: float = 1.0, max_rpm: float = 3000.0,
          min_load: float = 0.0, max_friction: float = 1.0, couplings=COUPLINGS,
          gravity=(True, False), errors: bool = True) -> st.SearchStrategy[dict]:
    """Scene parameters inside the scene's validation (beta in [0, 90) deg, non-zero speed)."""
    return st.fixed_dictionaries({
        "base": st.sampled_from(("paper-literal", "paper-matched")),
        "shaft_angle_deg": _maybe_zero(max_angle),
        "speed_rpm": st.floats(min_rpm, max_rpm),
        "direction": st.sampled_from((1, -1)),
        "load": st.floats(min_load, 10.0) if min_load > 0 else _maybe_zero(10.0),
        "f_spider": _maybe_zero(max_friction),
        "f_frame": _maybe_zero(max_friction),
        "coupling": st.sampled_from(tuple(couplings)),
        "gravity": st.sampled_from(tuple(gravity)),
        "errors": st.one_of(st.none(), ERRORS) if errors else st.none(),
    })


@functools.cache
def _base(name: str):
    return named_scene(name)


def scene_of(cell: dict):
    """The scene of a cell: one revolution, the load resisting the motion in either direction."""
    d = cell["direction"]
    changes = {
        "joint.geometry.shaft_angle": cell["shaft_angle_deg"] * DEG,
        "drive.speed": d * cell["speed_rpm"] * RPM,
        "load.torque": d * cell["load"],
        "friction.coupling": cell["coupling"],
        "gravity": (0.0, 0.0, -9.81) if cell["gravity"] else (0.0, 0.0, 0.0),
        "revolutions": 1.0,
        "numerics.accuracy": cell.get("accuracy", ACCURACY),
    }
    for pair in ("input_spider", "spider_output"):
        changes[f"joint.pairs.{pair}.friction_coefficient"] = cell["f_spider"]
    for pair in ("frame_input", "output_frame"):
        changes[f"joint.pairs.{pair}.friction_coefficient"] = cell["f_frame"]
    for name, value in (cell["errors"] or {}).items():
        changes[f"joint.errors.{name}"] = value * DEG if name.startswith("alpha") else value
    return replace(_base(cell["base"]), **changes)


def run_cell(cell: dict, engine: str, node_type: str = "Rxyz"):
    """Run a cell; Exudyn at the speed-ratio step of ``ACCURACY`` unless the cell sets its own
    accuracy (then at the automatic step, which meets that accuracy on the mean efficiency)."""
    scene = scene_of(cell)
    if engine == "reference":
        return scene, run_engine(scene, "reference")
    if "accuracy" not in cell:
        scene = replace(scene, **{"numerics.dt": choose_step(scene, node_type)[0]})
    return scene, run_engine(scene, options=ExudynOptions(node_type=node_type))


# --------------------------------------------------------------------------- measures

def _record(kind: str, value: float, cell: dict) -> None:
    """Append a measured ratio to $PROPERTIES_LOG (JSON lines), to re-measure the constants."""
    path = os.environ.get("PROPERTIES_LOG")
    if path:
        with open(path, "a", encoding="utf-8") as f:
            f.write(json.dumps({"kind": kind, "value": float(value), "cell": cell}) + "\n")


def energy_scale(table) -> float:
    """``S``: gross energy flow over the run plus the largest kinetic energy [J]."""
    t = table["t"].to_numpy()
    flow = np.abs(table["power_in"]) + np.abs(table["power_out"]) + np.abs(table["power_loss"])
    return float(np.trapezoid(flow.to_numpy(), t) + table["energy_kinetic"].abs().max())


def energy_change(result) -> float:
    """Change of mechanical energy over the whole revolutions [J] (as ``balance_residual``)."""
    s, t = result.summary, result.table
    energy = (t["energy_kinetic"] + t["energy_potential"]).to_numpy()
    theta = t["theta_in"].to_numpy()
    sign = 1.0 if theta[-1] >= theta[0] else -1.0
    end = theta[0] + sign * 2 * math.pi * s.revolutions
    if sign < 0:
        theta, end, start = -theta, -end, -theta[0]
    else:
        start = theta[0]
    return float(np.interp(end, theta, energy) - np.interp(start, theta, energy))


def signed_balance_residual(result) -> tuple[float, float]:
    """``balance_residual`` for either direction of rotation (it interpolates in theta, which
    must increase)."""
    t = result.table
    if t["theta_in"].iloc[-1] >= t["theta_in"].iloc[0]:
        return balance_residual(result)
    s = result.summary
    return (s.input_work - s.output_work - s.loss_work - energy_change(result),
            s.input_work)


def angle_step(scene, result) -> float:
    """``h = omega dt``, the input-angle step [rad]."""
    return abs(scene.drive.speed) * result.summary.dt


def balance_tolerance(scene, result, engine: str) -> float:
    """Allowed |W_in - W_out - W_loss - dE| [J] (module docstring)."""
    s_scale = energy_scale(result.table)
    if engine == "reference":
        return REF_BALANCE * s_scale
    k = error_coefficient(scene.joint.geometry.shaft_angle)
    return C_E * (1.0 + k) * angle_step(scene, result) ** 2 * s_scale


def efficiency_tolerance(scene, exudyn) -> float:
    """Allowed |eta_exudyn - eta_reference| (module docstring)."""
    s = exudyn.summary
    h = angle_step(scene, exudyn)
    k = error_coefficient(scene.joint.geometry.shaft_angle)
    w_in, w_loss = abs(s.input_work), abs(s.loss_work)
    bound = h * h * (1.0 + k) * (C_1 * energy_scale(exudyn.table) + C_2 * w_loss)
    if scene.friction.coupling == "lagged":
        bound += C_LAG * h * w_loss
    return bound / w_in


# --------------------------------------------------------------------------- checks

def check_status_contract(result, engine: str) -> None:
    s = result.summary
    status, reason = s.status, s.reason
    assert status in STATUSES[engine], (status, reason)
    assert isinstance(reason, str), reason
    if status == "ok":
        assert reason == "", reason
        return
    assert reason.strip(), f"status {status!r} without a reason"
    shown = {k: getattr(s, k) for k in EFFICIENCY_KEYS if getattr(s, k) is not None}
    assert not shown, f"status {status!r} presents efficiencies {shown}"


def check_finite(result, engine: str) -> None:
    s, t = result.summary, result.table
    assert t is not None and len(t) >= 2
    bad = [c for c in t.columns
           if c != "efficiency" and not np.all(np.isfinite(t[c].to_numpy(dtype=float)))]
    assert not bad, f"non-finite values in an ok table: {bad}"
    undefined = t["power_in"].to_numpy() == 0.0
    eta = t["efficiency"].to_numpy()
    assert np.all(np.isnan(eta[undefined]))
    # uncoupled: the input power does not pay the loss; with no load it is rounding noise and
    # eq. (18) overflows (test_uncoupled_without_load_has_no_efficiency, a known defect)
    overflow_allowed = uncoupled_without_work(result)
    assert overflow_allowed or np.all(np.isfinite(eta[~undefined]))
    numbers = {k: v for k, v in s.to_dict().items()
               if isinstance(v, (int, float, np.floating)) and not isinstance(v, bool)}
    for key in ("input_work", "output_work", "loss_work"):
        assert key in numbers, key
    # an undefined mean is None with a warning saying why (issue 18), never NaN
    for key in ("mean_efficiency", "mean_instantaneous_efficiency", "work_ratio"):
        assert key in numbers or (getattr(s, key) is None and s.warnings), key
    bad = [k for k, v in numbers.items() if not math.isfinite(v)]
    assert not bad, {k: numbers[k] for k in bad}
    assert s.revolutions >= 1


def uncoupled_without_work(result) -> bool:
    """An uncoupled run whose input work is rounding noise of its energy scale (no load, or a
    load as good as none: hypothesis tries 2e-313 N m)."""
    coupling = result.summary.scene["friction"]["coupling"]
    return (coupling == "uncoupled"
            and abs(result.summary.input_work) <= 1e-9 * energy_scale(result.table))


def check_efficiency_column(scene, result, engine: str) -> None:
    t = result.table
    p_in, loss = t["power_in"].to_numpy(), t["power_loss"].to_numpy()
    eta = t["efficiency"].to_numpy()
    defined = p_in != 0.0
    # eq. (18) as stated
    with np.errstate(over="ignore"):
        np.testing.assert_allclose(eta[defined], 1.0 - loss[defined] / p_in[defined], rtol=1e-12,
                                   atol=0)
    if not scene.has_friction:
        assert np.all(loss == 0.0)
        assert np.all(eta[defined] == 1.0)
        return
    # friction never generates power
    if engine == "reference":
        assert loss.min() >= 0.0, loss.min()
    elif scene.friction.coupling == "converged":
        assert loss.min() >= -fixed_point_slack(scene, t), (loss.min(), fixed_point_slack(scene, t))


def fixed_point_slack(scene, table) -> float:
    """Largest power a converged friction load may generate: its fixed-point residual (tolerance
    times the largest friction load, forces counted at the journal radius) times the relative
    speeds, summed over the pairs."""
    loads = [table[f"{p}_friction_torque"].abs().max() for p in PAIR_NAMES]
    speeds = 0.0
    for name, pair in scene.joint.pairs.items():
        d = pair.journal_diameter
        loads.append(0.5 * d * table[f"{name}_friction_force"].abs().max())
        speeds += table[f"{name}_omega_rel"].abs().max()
        if PAIR_KIND[name] == "cylindrical":
            speeds += 2.0 / d * table[f"{name}_slide_rel"].abs().max()
    return 2.0 * scene.friction.tolerance * max(loads) * speeds


def check_energy_and_means(scene, result, engine: str, cell: dict) -> None:
    s = result.summary
    residual, w_in = signed_balance_residual(result)
    w_loss, w_out = s.loss_work, s.output_work
    tol = balance_tolerance(scene, result, engine)
    uncoupled = scene.friction.coupling == "uncoupled"
    if uncoupled:  # friction is not in the dynamics: the input work pays no loss
        residual += w_loss
    _record(f"balance/{engine}", abs(residual) / (tol / (C_E if engine == "exudyn" else REF_BALANCE)),
            cell)
    assert abs(residual) <= tol, (residual, tol, w_in)
    eta = s.mean_efficiency
    if s.power_flow == "none":  # no shaft takes net work (no load): nothing is transmitted
        # undefined only when no work is lost either (to WORK_FLOOR of the window's energy scale,
        # which counts the potential energy too: 1e-6 of the kinetic scale is a loose bound)
        assert eta == 0.0 or (eta is None and w_loss <= 1e-6 * energy_scale(result.table)), (eta, w_loss)
        return
    assert s.power_flow == "input_to_output", s.power_flow  # the load resists
    assert 0.0 <= eta <= 1.0, eta
    assert eta == pytest.approx(1.0 - w_loss / w_in, rel=1e-12, abs=1e-12)
    if not scene.has_friction:
        assert eta == 1.0
        if s.power_reversals == 0:  # else undefined: the input power changes sign (issue 18)
            assert s.mean_instantaneous_efficiency == pytest.approx(1.0, abs=1e-12)
        else:
            assert s.mean_instantaneous_efficiency is None
        return
    assert w_out >= -tol, (w_out, tol)        # the load resists: it only takes power
    assert w_loss >= -tol, (w_loss, tol)      # friction only dissipates
    if w_in <= tol:  # no input work to within the balance: the quotient is 0/0 within error
        assert w_in >= -tol - abs(energy_change(result)), (w_in, tol)
        return
    assert eta <= 1.0 + max(0.0, -w_loss) / w_in, eta
    if not uncoupled:
        lower = -(tol + max(0.0, -energy_change(result))) / w_in
        assert eta >= lower, (eta, lower)


def check_invariants(cell: dict, engine: str, node_type: str = "Rxyz"):
    scene, result = run_cell(cell, engine, node_type)
    check_status_contract(result, engine)
    if result.success:
        check_finite(result, engine)
        check_efficiency_column(scene, result, engine)
        check_energy_and_means(scene, result, engine, cell)
    return scene, result


# --------------------------------------------------------------------------- settings

def budget(examples: int) -> settings:
    """Reproducible: derandomized, no example database, no deadline (the runs take seconds)."""
    return settings(max_examples=examples, deadline=None, derandomize=True, database=None,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])


# examples per property: default (about 20 s in all on one core) and -m slow (about 5 min)
FAST, SLOW = 100, 1500
FAST_EXUDYN, SLOW_EXUDYN = 50, 600
FAST_AGREE, SLOW_AGREE = 40, 500
FAST_QUASI_STATIC, SLOW_QUASI_STATIC = 20, 300


# --------------------------------------------------------------------------- reference engine

@budget(FAST)
@given(cells())
def test_reference_invariants(cell):
    check_invariants(cell, "reference")


@pytest.mark.slow
@budget(SLOW)
@given(cells())
def test_reference_invariants_many(cell):
    check_invariants(cell, "reference")


# --------------------------------------------------------------------------- Exudyn

#: found by hypothesis: the largest balance constant, 0.102 (second order: 0.1009 / 0.1017 /
#: 0.1022 / 0.1024 at 100 / 200 / 400 / 800 steps), spider friction 1 near locking (loop gain 0.92)
STRONG_SPIDER_FRICTION = {"base": "paper-literal", "shaft_angle_deg": 30.0, "speed_rpm": 14.0, "direction": 1,
                          "load": 1.0, "f_spider": 1.0, "f_frame": 0.0, "coupling": "converged",
                          "gravity": True, "errors": None}
#: found by hypothesis: Exudyn reported self_locking at 0 deg (spider pairs at rest, their friction
#: rounding noise that the relative fixed-point tolerance could never meet); fixed in
#: cardan_exudyn/model/coupling.py (REST_FLOOR); lagged, the growth of that noise out of rounding was
#: taken for the geometric growth of a locking loop
SPIDER_AT_REST = {"base": "paper-literal", "shaft_angle_deg": 0.0, "speed_rpm": 1.0, "direction": 1,
                  "load": 0.0,
                  "f_spider": 0.5, "f_frame": 0.0, "coupling": "converged", "gravity": True,
                  "errors": None}
SPIDER_AT_REST_LAGGED = {**SPIDER_AT_REST, "coupling": "lagged"}


@budget(FAST_EXUDYN)
@given(cells(), st.sampled_from(NODE_TYPES))
@example(STRONG_SPIDER_FRICTION, "Rxyz")
@example(SPIDER_AT_REST, "Rxyz")
@example(SPIDER_AT_REST_LAGGED, "EP")
def test_exudyn_invariants(cell, node_type):
    check_invariants(cell, "exudyn", node_type)


@pytest.mark.slow
@budget(SLOW_EXUDYN)
@given(cells(), st.sampled_from(NODE_TYPES))
def test_exudyn_invariants_many(cell, node_type):
    check_invariants(cell, "exudyn", node_type)


# --------------------------------------------------------------------------- quasi-static

QUASI_STATIC = cells(max_angle=45.0, max_rpm=60.0, min_load=0.2, gravity=(False,),
                     couplings=("converged", "lagged"))


def check_quasi_static(cell: dict, engine: str) -> None:
    """Where the power flows one way, eq. (18) and its time average are in [0, 1]."""
    scene, result = check_invariants(cell, engine)
    if not result.success:
        return
    t = result.table
    energy = (t["energy_kinetic"] + t["energy_potential"]).to_numpy()
    inertial = np.abs(np.gradient(energy, t["t"].to_numpy())).max()
    # the strategy's bounds (45 deg, 60 rpm, 0.2 N m) admit a few cells near 40 deg whose inertial
    # power reaches 1 % of the output power (found at 39 deg, 40 rpm, 0.25 N m): the law below is
    # claimed for quasi-static cells only, so those are filtered out, not failed
    assume(inertial <= 0.01 * t["power_out"].abs().min())
    eta = t["efficiency"].to_numpy()
    slack = 0.0
    if engine == "exudyn":  # the friction's fixed-point residual over the smallest input power
        slack = fixed_point_slack(scene, t) / t["power_in"].abs().min()
    assert eta.min() >= -slack and eta.max() <= 1.0 + slack, (eta.min(), eta.max())
    mean = result.summary.mean_instantaneous_efficiency
    assert mean is not None and 0.0 <= mean <= 1.0, (mean, result.summary.warnings)


@budget(FAST_QUASI_STATIC)
@given(QUASI_STATIC)
def test_quasi_static_efficiency_in_unit_interval_reference(cell):
    check_quasi_static(cell, "reference")


@budget(FAST_QUASI_STATIC // 2)
@given(QUASI_STATIC.map(lambda c: {**c, "coupling": "converged"}))
def test_quasi_static_efficiency_in_unit_interval_exudyn(cell):
    check_quasi_static(cell, "exudyn")


@pytest.mark.slow
@budget(SLOW_QUASI_STATIC)
@given(QUASI_STATIC, st.sampled_from(("reference", "exudyn")))
def test_quasi_static_efficiency_in_unit_interval_many(cell, engine):
    if engine == "exudyn":
        cell = {**cell, "coupling": "converged"}
    check_quasi_static(cell, engine)


# --------------------------------------------------------------------------- engines agree

INSIDE = cells(max_angle=50.0, min_load=0.2, max_friction=0.5, couplings=("converged", "lagged"),
               errors=False).map(lambda cell: {**cell, "accuracy": AGREE_ACCURACY})


def check_engines_agree(cell: dict) -> None:
    scene, ref = check_invariants(cell, "reference")
    assume(ref.success and ref.summary.max_friction_loop_gain <= CLEARLY_OK_GAIN)
    _, exu = check_invariants(cell, "exudyn")
    assert exu.success, (exu.summary.status, exu.summary.reason)
    if not scene.has_friction:
        assert exu.summary.mean_efficiency == ref.summary.mean_efficiency == 1.0
        return
    if ref.summary.mean_efficiency is None:  # nothing transmitted or lost (the spider at rest)
        assert exu.summary.mean_efficiency in (None, 0.0), exu.summary.mean_efficiency
        return
    difference = exu.summary.mean_efficiency - ref.summary.mean_efficiency
    bound = efficiency_tolerance(scene, exu)
    _record(f"efficiency/{scene.friction.coupling}", abs(difference) / bound, cell)
    assert abs(difference) <= bound, (difference, bound)


@budget(FAST_AGREE)
@given(INSIDE)
@example(SPIDER_AT_REST)
@example(SPIDER_AT_REST_LAGGED)
def test_engines_agree_inside_ok_region(cell):
    check_engines_agree(cell)


@pytest.mark.slow
@budget(SLOW_AGREE)
@given(INSIDE)
def test_engines_agree_inside_ok_region_many(cell):
    check_engines_agree(cell)


# --------------------------------------------------------------------------- locking boundary

def check_locking_between_samples(angle_deg: float, samples: int) -> None:
    """Status contract of the reference engine where friction locks over narrow arcs only, with
    a coarse table: the locking is then found at quadrature nodes between the samples."""
    cell = {"base": "paper-literal", "shaft_angle_deg": angle_deg, "speed_rpm": 2000.0, "direction": 1,
            "load": 2.0, "f_spider": 0.42, "f_frame": 0.2, "coupling": "converged", "gravity": True,
            "errors": None}
    scene = scene_of(cell)
    result = run_engine(scene, options=ReferenceOptions(samples_per_revolution=samples))
    check_status_contract(result, "reference")
    if result.success:
        check_finite(result, "reference")


@budget(15)
@given(st.floats(44.0, 52.0), st.integers(3, 40))
@example(47.0, 4)  # was: self_locking with mean_efficiency NaN, mean_instantaneous 0.22 (fixed)
def test_reference_locking_between_samples_presents_no_efficiency(angle_deg, samples):
    check_locking_between_samples(angle_deg, samples)


# --------------------------------------------------------------------------- pinned examples

def test_statuses_seen_include_locking_and_ok():
    """Both sides of the self-locking boundary: the plain set locks at 50 deg, runs at 10 deg
    (README)."""
    base = {"base": "paper-literal", "speed_rpm": 2000.0, "direction": 1, "load": 2.0, "f_spider": 0.42,
            "f_frame": 0.2, "coupling": "converged", "gravity": True, "errors": None}
    locked = check_invariants({**base, "shaft_angle_deg": 50.0}, "reference")[1]
    assert locked.summary.status == "self_locking"
    assert check_invariants({**base, "shaft_angle_deg": 10.0}, "reference")[1].success


def test_instantaneous_efficiency_is_not_bounded():
    """45 deg (literal set, reference): the input power changes sign, eq. (18) has poles and its
    time average is not reported (None, with a warning); the mean efficiency is 0.071."""
    cell = {"base": "paper-literal", "shaft_angle_deg": 45.0, "speed_rpm": 2000.0, "direction": 1,
            "load": 2.0, "f_spider": 0.42, "f_frame": 0.2, "coupling": "converged",
            "gravity": True, "errors": None}
    _, result = check_invariants(cell, "reference")
    s, t = result.summary, result.table
    # the reference's value (exact to its quadrature, 1e-9) to the digits stated (docs/paper.md:
    # 0.070914)
    assert result.success and abs(s.mean_efficiency - 0.071) <= 5e-4, s.mean_efficiency
    assert s.mean_instantaneous_efficiency is None and s.power_reversals > 0
    assert any("changes sign" in w and "eq. (18) is undefined" in w for w in s.warnings), s.warnings
    assert (t["power_in"] < 0).any()


def test_uncoupled_without_load_has_no_efficiency():
    """Falsifying example (hypothesis, reference engine): uncoupled friction estimates the loss on
    the frictionless reactions, so the input work pays no loss; without load it is zero up to
    rounding and the quotient was noise (measured 7e15; the column overflows to inf at 1 rpm).
    Fixed (issue 18): no shaft takes net work, the efficiency is 0 (nothing is transmitted)."""
    cell = {"base": "paper-literal", "shaft_angle_deg": 20.0, "speed_rpm": 1000.0, "direction": 1,
            "load": 0.0, "f_spider": 0.5, "f_frame": 0.2, "coupling": "uncoupled",
            "gravity": False, "errors": None}
    s = run_engine(scene_of(cell), "reference").summary
    assert s.status == "ok", s.reason
    assert s.power_flow == "none" and s.mean_efficiency == 0.0, (s.power_flow, s.mean_efficiency)
