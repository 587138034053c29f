"""Power flowing either way (issue 18): reversed scenes, aiding loads, and no efficiency outside
[0, 1] with status ok, in every engine.

The reversal law: the mirror image of the joint in the plane of the shafts (z -> -z: the bodies'
centres of mass and products of inertia, and gravity, mirrored) running with speed and load
reversed (an angle history negated, a torque drive reversed) has the same reactions, the same
friction and so the same efficiency as the original. A joint whose bodies are symmetric about that
plane is its own mirror image: reversing it changes nothing. The paper's bodies are not (the input
shaft's centre of mass is 8.6 mm off the plane, and it has products of inertia with z), so its
reversed scene differs by 3e-5 in efficiency (reference, gravity off), which is physics.

Tolerances: the reference engine solves each sample exactly and integrates the works to
``quadrature_rtol`` (1e-9) of their scale, on panels that mirror each other: the efficiencies
agree to 10 x that (measured: bit for bit). Exudyn solves the same discrete equations in both
runs except for the rotation parametrisation, so they differ by where the Newton iteration
(1e-10) and the friction fixed point (relative change of the friction loads ``friction.tolerance``,
1e-6) stop: 10 x ``friction.tolerance`` in efficiency (measured: at most 1.3e-10 on the examples,
6e-9 on the paper scene at 2000 rpm).
"""

from __future__ import annotations

import json
import math
import re

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from cardan_exudyn import run as run_engine
from cardan_exudyn.cli import main
from cardan_exudyn.studies.stress.classify import cell_class
from cardan_exudyn.sweep.records import scalar_summary
from cardan_exudyn.testing.assertions import check_flow
from reference.engine.options import ReferenceOptions
from reference.paper.scenes import named_scene
from reference.results.power_flow import PowerFlow, classify_works, sign_changes
from reference.results.result import Result
from reference.results.summary import SCHEMA_VERSION, Status, Summary
from reference.scene.mapping import replace
from reference.scene.validation import DEG, RPM

MIRROR = np.diag([1.0, 1.0, -1.0])
REFERENCE_TOL = 10 * ReferenceOptions().quadrature_rtol
ENGINES = ("reference", "exudyn")


def budget(examples: int) -> settings:
    """Reproducible: derandomized, no example database, no deadline (the runs take seconds)."""
    return settings(max_examples=examples, deadline=None, derandomize=True, database=None,
                    suppress_health_check=[HealthCheck.too_slow])


def mirrored_body(body) -> dict:
    """The body's mirror image in the plane of the shafts, in canonical axes about its centre
    of mass."""
    mass, com, inertia = body.canonical()
    return {"mass": mass, "com": (MIRROR @ com).tolist(), "inertia": (MIRROR @ inertia @ MIRROR).tolist()}


def reversed_scene(scene, mirror: bool = True):
    """``scene`` run backwards: speed (angle history, torque drive) and load reversed; with
    ``mirror`` also the mirror image of its bodies and gravity."""
    changes = {"load.torque": -scene.load.torque}
    drive = scene.drive
    if drive.kind == "speed":
        changes["drive.speed"] = -drive.speed
    elif drive.kind == "angle":
        changes["drive"] = {"kind": "angle", "time": list(drive.time), "angle": [-a for a in drive.angle]}
    else:
        changes["drive"] = {"kind": "torque", "torque": -drive.torque, "initial_speed": -drive.initial_speed}
    if mirror:
        changes.update({f"joint.{name}": mirrored_body(getattr(scene.joint, name))
                        for name in ("input", "spider", "output")})
        changes["gravity"] = (MIRROR @ np.asarray(scene.gravity)).tolist()
    return replace(scene, **changes)


def symmetric_joint(scene):
    """``scene`` with bodies symmetric about the plane of the shafts (centres of mass in it, no
    products of inertia with z): its own mirror image."""
    changes = {}
    for name in ("input", "spider", "output"):
        mass, com, inertia = getattr(scene.joint, name).canonical()
        inertia = inertia.copy()
        inertia[0, 2] = inertia[2, 0] = inertia[1, 2] = inertia[2, 1] = 0.0
        changes[f"joint.{name}"] = {"mass": mass, "com": [com[0], com[1], 0.0], "inertia": inertia.tolist()}
    return replace(scene, **changes)


CELLS = st.fixed_dictionaries({
    "angle_deg": st.floats(0.0, 40.0),
    "rpm": st.floats(100.0, 3000.0),
    "load": st.floats(-5.0, 5.0),
    "f_spider": st.floats(0.0, 0.4),
    "f_frame": st.floats(0.0, 0.4),
    "gravity": st.sampled_from((0.0, 9.81)),
    "history": st.booleans(),
})


#: and steps per revolution fixed (0: the engine's choice), down to the issue's 7 steps for 2
#: revolutions, where Exudyn's efficiency came out as 27.4 with status ok
CONTRACT_CELLS = CELLS.flatmap(lambda c: st.sampled_from((0, 0, 4, 12, 40)).map(lambda n: {**c, "steps": n}))


def cell_scene(cell: dict):
    """One revolution of the paper's joint at a constant speed or along an angle history (the
    speed modulated by +-30 % at 1.5 times the shaft frequency), every revolution averaged."""
    w = cell["rpm"] * RPM
    changes = {"joint.geometry.shaft_angle": cell["angle_deg"] * DEG, "drive.speed": w,
               "load.torque": cell["load"], "gravity": (0.0, 0.0, -cell["gravity"]),
               "revolutions": 1.0, "record.skip_revolutions": 0.0}
    for pair in ("input_spider", "spider_output"):
        changes[f"joint.pairs.{pair}.friction_coefficient"] = cell["f_spider"]
    for pair in ("frame_input", "output_frame"):
        changes[f"joint.pairs.{pair}.friction_coefficient"] = cell["f_frame"]
    if cell.get("steps"):
        changes["numerics.dt"] = 2 * math.pi / w / cell["steps"]
    scene = replace(named_scene("paper-literal"), **changes)
    if not cell["history"]:
        return scene
    t = np.linspace(0.0, 1.2 * 2 * math.pi / w, 30)
    angle = w * t + 0.2 * np.sin(1.5 * w * t)  # speed w (1 + 0.3 cos): monotonic
    return replace(scene, drive={"kind": "angle", "time": t.tolist(), "angle": angle.tolist()})


# --------------------------------------------------------------------------- the law: [0, 1] or not ok

def check_efficiency_contract(summary: Summary) -> None:
    """Status ok: every efficiency in [0, 1] or None with a warning; the power flow matches the
    works' signs and the efficiency is that of its direction."""
    if not summary.success:
        assert summary.mean_efficiency is None and summary.mean_instantaneous_efficiency is None
        assert summary.reason
        return
    for key in ("mean_efficiency", "mean_instantaneous_efficiency"):
        value = getattr(summary, key)
        assert value is None or 0.0 <= value <= 1.0, (key, value)
        if value is None:
            assert summary.warnings, f"{key} is None without a warning"
    w_in, w_out, w_loss = summary.input_work, summary.output_work, summary.loss_work
    flow = summary.power_flow
    if flow == PowerFlow.INPUT_TO_OUTPUT:
        assert w_in > 0 and w_out > 0
        assert summary.mean_efficiency == pytest.approx(1.0 - w_loss / w_in, rel=1e-12, abs=1e-15)
    elif flow == PowerFlow.OUTPUT_TO_INPUT:
        assert w_in < 0 and w_out < 0
        assert summary.mean_efficiency == pytest.approx(1.0 - w_loss / -w_out, rel=1e-12, abs=1e-15)
        assert any("output to the input" in w for w in summary.warnings)
    else:
        assert flow == PowerFlow.NONE and summary.mean_efficiency in (0.0, None)


@pytest.mark.parametrize("engine", ENGINES)
@budget(15)
@given(cell=CONTRACT_CELLS)
def test_efficiency_in_unit_interval_or_status_not_ok(engine, cell):
    """Either way the speed and the load turn, resisting or aiding, at any step: status ok means
    every efficiency reported is in [0, 1] (or None, with a warning saying why)."""
    result = run_engine(replace(cell_scene(cell), **{"record.timeseries": False}), engine)
    check_efficiency_contract(result.summary)


@pytest.mark.parametrize("engine", ENGINES)
@budget(6)
@given(cell=CELLS)
def test_reversed_mirrored_scene_has_the_same_efficiency(engine, cell):
    """The mirror image run backwards (speed or angle history and load reversed, gravity
    mirrored) has the same works, power flow and efficiency."""
    scene = replace(cell_scene(cell), **{"record.timeseries": False})
    forward = run_engine(scene, engine).summary
    backward = run_engine(reversed_scene(scene), engine).summary
    assert forward.status == backward.status
    if not forward.success:
        return
    tol = REFERENCE_TOL if engine == "reference" else 10 * scene.friction.tolerance
    assert forward.power_flow == backward.power_flow
    for key in ("mean_efficiency", "mean_instantaneous_efficiency"):
        a, b = getattr(forward, key), getattr(backward, key)
        assert (a is None) == (b is None), (key, a, b)
        if a is not None:
            assert abs(a - b) <= tol, (key, a, b)
    scale = max(abs(forward.input_work), abs(forward.output_work))
    assert abs(forward.loss_work - backward.loss_work) <= tol * scale


@pytest.mark.parametrize("engine", ENGINES)
def test_symmetric_joint_reversed_gravity_off(engine):
    """Bodies symmetric about the plane of the shafts, gravity off: the reversed scene itself
    (no mirror needed) gives the forward efficiency."""
    scene = symmetric_joint(replace(named_scene("paper-literal"), gravity=(0.0, 0.0, 0.0), revolutions=1.0,
                                    **{"record.skip_revolutions": 0.0, "record.timeseries": False}))
    forward = run_engine(scene, engine).summary
    backward = run_engine(reversed_scene(scene, mirror=False), engine).summary
    assert forward.success and backward.success
    tol = REFERENCE_TOL if engine == "reference" else 10 * scene.friction.tolerance
    assert forward.power_flow == backward.power_flow == "input_to_output"
    assert abs(forward.mean_efficiency - backward.mean_efficiency) <= tol
    assert 0.0 < forward.mean_efficiency < 1.0


@pytest.mark.parametrize("engine", [pytest.param("reference", marks=pytest.mark.slow), "exudyn"])
def test_reversed_torque_drive(engine):
    """A torque drive reversed with its load, mirrored: the same efficiency (the reference
    integrates the drive's ODE, about 30 s with friction: slow; Exudyn steps it)."""
    scene = replace(named_scene("paper-literal"), gravity=(0.0, 0.0, 0.0), revolutions=1.0,
                    drive={"kind": "torque", "torque": 6.0, "initial_speed": 2000 * RPM},
                    **{"record.skip_revolutions": 0.0, "record.timeseries": False,
                       "joint.pairs.frame_input.friction_coefficient": 0.0,
                       "joint.pairs.output_frame.friction_coefficient": 0.0})
    forward = run_engine(scene, engine).summary
    backward = run_engine(reversed_scene(scene), engine).summary
    assert forward.success and backward.success, (forward.reason, backward.reason)
    check_efficiency_contract(forward)
    tol = REFERENCE_TOL if engine == "reference" else 10 * scene.friction.tolerance
    assert abs(forward.mean_efficiency - backward.mean_efficiency) <= tol


@pytest.mark.parametrize("engine", ENGINES)
def test_aiding_load_makes_the_output_the_source(engine):
    """The issue's `--rpm -2000` (the load aids the motion, the drive brakes): power flows from
    the output to the input, and its efficiency is 1 - W_loss / (-W_out), in [0, 1] (was 4.34);
    the mirror image (the forward speed with the load reversed) flows the same way."""
    scene = replace(named_scene("paper-literal"), revolutions=1.0, gravity=(0.0, 0.0, 0.0),
                    **{"record.skip_revolutions": 0.0})
    aiding_scene = replace(scene, **{"drive.speed": -scene.drive.speed})
    aiding = run_engine(aiding_scene, engine)
    s = aiding.summary
    assert s.success and s.power_flow == "output_to_input"
    assert s.input_work < 0 and s.output_work < 0
    check_efficiency_contract(s)
    # 0.23: the reference's value (exact to its quadrature, 1e-9) to the two digits stated; the
    # other engine independently to Exudyn's target accuracy (numerics.accuracy, the absolute
    # error of the mean efficiency its automatic step is chosen for; measured 1.3e-4 apart)
    other = run_engine(aiding_scene, "exudyn" if engine == "reference" else "reference").summary
    reference = s if engine == "reference" else other
    assert abs(reference.mean_efficiency - 0.23) <= 0.005, reference.mean_efficiency
    assert abs(s.mean_efficiency - other.mean_efficiency) <= scene.numerics.accuracy
    assert s.power_reversals == 0 and (aiding.table["power_out"] < 0).all()
    mirror = run_engine(reversed_scene(aiding_scene), engine).summary
    assert mirror.success and mirror.power_flow == "output_to_input"
    tol = REFERENCE_TOL if engine == "reference" else 10 * scene.friction.tolerance
    assert abs(mirror.mean_efficiency - s.mean_efficiency) <= tol
    assert sign_changes(np.array([1.0, 0.0, -2.0, -1.0, 3.0])) == 2


def test_mujoco_frictionless_either_way():
    """MuJoCo (optional, frictionless): an ideal joint transmits everything either way."""
    pytest.importorskip("mujoco")
    scene = replace(named_scene("paper-literal-frictionless"), revolutions=1.0, gravity=(0.0, 0.0, 0.0),
                    **{"record.skip_revolutions": 0.0, "record.timeseries": False})
    for changes, flow in (({}, "input_to_output"), ({"load.torque": -scene.load.torque}, "output_to_input")):
        s = run_engine(replace(scene, **changes), "mujoco").summary
        assert s.success and s.power_flow == flow, (s.status, s.reason, s.power_flow)
        assert s.mean_efficiency == 1.0


# --------------------------------------------------------------------------- edges

@pytest.mark.parametrize("engine", ENGINES)
def test_zero_work_edge(engine):
    """Frictionless and unloaded: undefined (None with a warning, was NaN or 1); with friction
    and no load: 0 (nothing transmitted); frictionless with a load: exactly 1."""
    base = replace(named_scene("paper-literal"), revolutions=1.0, **{"record.skip_revolutions": 0.0,
                                                            "record.timeseries": False})
    free = replace(named_scene("paper-literal-frictionless"), revolutions=1.0,
                   **{"record.skip_revolutions": 0.0, "record.timeseries": False})
    s = run_engine(replace(free, **{"load.torque": 0.0}), engine).summary
    assert s.success and s.mean_efficiency is None and s.power_flow == "none"
    assert any("undefined" in w for w in s.warnings)
    s = run_engine(replace(base, **{"load.torque": 0.0}), engine).summary
    assert s.success and s.mean_efficiency == 0.0 and s.power_flow == "none"
    s = run_engine(free, engine).summary
    assert s.success and s.mean_efficiency == 1.0 and s.power_flow == "input_to_output"


def test_coarse_step_is_unphysical():
    """The issue's `--dt 0.01` (7 steps for 2 revolutions, efficiency 27.4 with status ok):
    status unphysical with the values and the likely cause."""
    s = run_engine(replace(named_scene("paper-literal"), **{"numerics.dt": 0.01}), "exudyn").summary
    assert s.status is Status.UNPHYSICAL and s.mean_efficiency is None
    assert "too coarse" in s.reason


def test_time_average_of_eq18_not_reported_where_undefined():
    """At 35 deg eq. (18) averages -0.83 while the mean efficiency is 0.25: not reported (None)
    with the value in a warning; the mean efficiency stays."""
    scene = replace(named_scene("paper-literal-35deg"), revolutions=1.0,
                    **{"record.skip_revolutions": 0.0, "record.timeseries": False})
    s = run_engine(scene, "reference").summary
    # the reference's values (exact to its quadrature, 1e-9) to the digits the docstring states
    assert s.success and abs(s.mean_efficiency - 0.25) <= 0.005, s.mean_efficiency
    assert s.mean_instantaneous_efficiency is None
    [note] = [w for w in s.warnings if "eq. (18)" in w]
    average = float(re.search(r"eq\. \(18\), (\S+), is outside \[0, 1\]", note).group(1))
    assert abs(average - -0.83) <= 0.005, note


@pytest.mark.parametrize("works, flow, eta", [
    ((10.0, 6.0, 4.0), "input_to_output", 0.6),
    ((-6.0, -10.0, 4.0), "output_to_input", 0.6),
    ((3.0, -2.0, 5.0), "none", 0.0),
    ((0.0, 0.0, 5.0), "none", 0.0),
    ((1e-17, 0.0, 0.0), "none", None),
    ((-1e-17, 0.0, 0.0), "none", None),
], ids=["forward", "reverse", "both-supply", "no-load", "free", "free-rounding"])
def test_classify_works(works, flow, eta):
    """Each direction and its efficiency, by hand (energy balance closed: W_in = W_out + W_loss)."""
    verdict = classify_works(*works, energy_scale=1.0)
    assert verdict.power_flow == flow and verdict.mean_efficiency == eta and not verdict.problem


@pytest.mark.parametrize("works, match", [
    ((10.0, 6.0, 11.0), "outside"), ((-2.0, 3.0, 0.0), "nobody supplies"),
    ((10.0, 6.0, -1.0), "friction generates"), ((math.nan, 1.0, 1.0), "non-finite")])
def test_impossible_works_are_problems(works, match):
    """Works no periodic window can have are a problem, not an efficiency."""
    verdict = classify_works(*works)
    assert verdict.mean_efficiency is None and match in verdict.problem


# --------------------------------------------------------------------------- schema and consumers

def test_schema_3_round_trip_and_older_versions_upgraded():
    """Version 3 writes the flow and the warnings and reads them back; a version-2 summary with a
    reversed flow (efficiency 4.3 with status ok) is read by version 3's rules."""
    s = run_engine(replace(named_scene("paper-literal"), revolutions=1.0,
                           **{"record.skip_revolutions": 0.0, "record.timeseries": False,
                              "drive.speed": -2000 * RPM}), "reference").summary
    data = json.loads(json.dumps(s.to_dict()))
    assert data["schema_version"] == SCHEMA_VERSION == 3
    again = Summary.from_dict(data)
    assert again.to_dict() == data and again.power_flow == "output_to_input" and again.warnings
    old = {**data, "schema_version": 2, "mean_efficiency": 4.338, "power_flow": None, "warnings": []}
    upgraded = Summary.from_dict(old)
    assert upgraded.success and upgraded.power_flow == "output_to_input"
    assert upgraded.mean_efficiency == pytest.approx(s.mean_efficiency, rel=1e-12)
    broken = {**old, "output_work": 5.0, "input_work": 1.0, "loss_work": 10.0}
    assert Summary.from_dict(broken).status is Status.UNPHYSICAL


def test_sweep_record_keeps_flow_and_warnings():
    """A sweep record has the power flow and the warnings as one text."""
    summary = Summary(Status.OK, power_flow="output_to_input", power_reversals=0,
                      warnings=["power flows from the output to the input", "second"])
    record = scalar_summary(summary)
    assert record["power_flow"] == "output_to_input" and record["power_reversals"] == 0
    assert record["warnings"] == "power flows from the output to the input; second"


def test_consumers_of_unphysical():
    """The stress map counts Exudyn's unphysical as a numerical failure (not an unexpected
    status); assertions refuse engines whose power flows differ."""
    assert cell_class({"exu_status": "unphysical"}) == ("integration_failure", [])
    a = Result(None, Summary(Status.OK, power_flow="input_to_output"))
    b = Result(None, Summary(Status.OK, power_flow="output_to_input"))
    assert check_flow(a, a) == [] and check_flow(a, b)[0].failed


def test_cli_prints_the_flow_and_exits_3_when_unphysical(capsys):
    """`cardan run --rpm -2000`: exit 0, the efficiency in [0, 1] and the flow's direction
    printed; a 7-step run: exit 3 with status unphysical."""
    assert main(["run", "--name", "paper-literal", "--rpm", "-2000", "--engine", "reference",
                 "--revolutions", "1"]) == 0
    out, err = capsys.readouterr()
    eta = float(re.search(r"mean efficiency ([0-9.]+)", out).group(1))
    assert 0.0 <= eta <= 1.0 and "power flow output_to_input" in out
    assert "warning: power flows from the output to the input" in err
    assert main(["run", "--name", "paper-literal", "--dt", "0.01"]) == 3
    out, err = capsys.readouterr()
    assert "status: unphysical" in err and "mean efficiency" not in out


def test_uncoupled_friction_without_load_transmits_nothing():
    """The defect pinned by a strict xfail before issue 18 (a falsifying example of the property
    tests): uncoupled friction estimates the loss on the frictionless reactions, so without a load
    the input work is rounding noise and 1 - W_loss / W_in was +-1e16 with status ok. Now nothing
    is transmitted: flow ``none``, efficiency 0, in [0, 1]."""
    scene = replace(named_scene("paper-literal-20deg-1000rpm"), **{
        "load.torque": 0.0, "gravity": (0.0, 0.0, 0.0), "friction.coupling": "uncoupled",
        "joint.pairs.input_spider.friction_coefficient": 0.5,
        "joint.pairs.spider_output.friction_coefficient": 0.5})
    s = run_engine(scene, "reference").summary
    assert s.status == Status.OK, s.reason
    assert s.power_flow == "none" and s.mean_efficiency == 0.0, (s.power_flow, s.mean_efficiency)
