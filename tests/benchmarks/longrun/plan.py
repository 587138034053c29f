"""What the long runs (:mod:`.runs`) run: the scenes, the variants (:data:`FULL`,
:data:`QUICK`), the Exudyn cases of the energy study, and the model of generalized-alpha's
energy loss the measurements are compared with.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from benchmarks.longrun.measures import damping_coefficient
from cardan_exudyn.model.options import NODE_TYPES, ExudynOptions
from cardan_exudyn.model.stepsize import choose_step
from reference.paper import named_scene
from reference.scene import replace
from reference.scene.scene import Scene

__all__ = ["ENGINE", "REFERENCE", "DRIFT_SCENE", "DRIFT_STEPS_PER_REVOLUTION", "ENERGY_SPEED_RPM",
           "RHO_LADDER_STEPS", "DEFAULT_RHO", "STARTUP_REVOLUTIONS", "DISSIPATION_MODEL",
           "RHO_MODEL", "LongRunPlan", "FULL", "QUICK", "drift_scene", "energy_scene",
           "automatic_steps", "energy_plan", "case_label", "model_loss", "settings"]

#: The engine whose long runs are measured, and the one measuring it (no time steps to drift).
ENGINE = "exudyn"
REFERENCE = "reference"
DRIFT_SCENE = "paper-literal-10deg-2000rpm"
# The step of the drift runs, the same for every node type: the automatic step of Rxyz nodes at 10
# deg for a speed-ratio error of 1e-5, given, so that the figures of docs/benchmarks.md stay
# comparable. One common step keeps the node types comparable and EP's run affordable (its own
# automatic step at that accuracy, 480 steps per revolution, would triple its 2000 revolutions).
DRIFT_STEPS_PER_REVOLUTION = 156
ENERGY_SPEED_RPM = 2000.0
RHO_LADDER_STEPS = 200               # steps per revolution of the spectral-radius ladder
DEFAULT_RHO = ExudynOptions().spectral_radius

# Revolutions at the start left out of the efficiency trend and the first/last comparison: the
# first revolution starts from the assembled state with zero velocity-constraint residuals, which
# settle to their periodic O(h^2) values within it (its efficiency differs by 2e-4 from the
# following ones; from the second revolution on they agree to 1e-8).
STARTUP_REVOLUTIONS = 1

# Relative energy lost per revolution by the free-spinning joint: K c(rho) h^3, with c(rho) the
# linear-oscillator damping coefficient of generalized-alpha (damping_coefficient) and
# h = 2 pi / (steps per revolution at the mean speed). K per shaft angle, fitted to the steady loss
# (second half of 1000 revolutions) of the step ladder (100 to 741 steps per revolution at rho 0.6)
# and the spectral radii 0.3 to 0.9 at 200 steps per revolution: 10 deg 4.02 (seven cases within
# 0.8 %), 35 deg 6.44 (within 1.3 %). Outside that range the loss per revolution is not steady:
# rho = 0 loses 6 % / 11 % of the energy over the run (the joint slows down), and at rho = 0.95 the
# steady loss (1e-9 per revolution) is at the level of the slow wander of the energy error.
DISSIPATION_MODEL = {10.0: 4.02, 35.0: 6.44}
RHO_MODEL = (0.3, 0.9)


@dataclass(frozen=True)
class LongRunPlan:
    """A variant of the long runs.

    Attributes
    ----------
    name : str
        ``"full"``, ``"quick"`` or a caller's own.
    drift_revolutions : int
        Input revolutions of each drift run with friction.
    node_types : tuple of str
        Node types of the drift runs (``ExudynOptions.node_type``).
    energy_revolutions : int
        Revolutions of each free-spinning Exudyn run.
    energy_angles : tuple of float
        Shaft angles of the energy study [deg].
    step_ladder : tuple of int
        Steps per revolution at the default spectral radius.
    rho_ladder : tuple of float
        Spectral radii at :data:`RHO_LADDER_STEPS` steps per revolution.
    reference_revolutions : int
        Revolutions of the reference engine's free-spinning run.
    """

    name: str
    drift_revolutions: int
    node_types: tuple[str, ...]
    energy_revolutions: int
    energy_angles: tuple[float, ...]
    step_ladder: tuple[int, ...]
    rho_ladder: tuple[float, ...]
    reference_revolutions: int

    @property
    def quick(self) -> bool:
        """Any variant but the full one."""
        return self.name != "full"


FULL = LongRunPlan("full", drift_revolutions=2000, node_types=NODE_TYPES, energy_revolutions=1000,
                   energy_angles=(10.0, 35.0), step_ladder=(100, 200, 400),
                   rho_ladder=(0.0, 0.3, 0.6, 0.8, 0.9, 0.95, 0.99), reference_revolutions=20)
QUICK = LongRunPlan("quick", drift_revolutions=20, node_types=("Rxyz", "EP"), energy_revolutions=20,
                    energy_angles=(35.0,), step_ladder=(100, 200, 400), rho_ladder=(0.3, 0.6, 0.9),
                    reference_revolutions=2)


def drift_scene(revolutions: int) -> Scene:
    """The paper's scene with friction at :data:`DRIFT_STEPS_PER_REVOLUTION`, summary only."""
    scene = named_scene(DRIFT_SCENE)
    dt = 2.0 * math.pi / scene.drive.speed / DRIFT_STEPS_PER_REVOLUTION
    return replace(scene, revolutions=float(revolutions),
                   **{"record.timeseries": False, "numerics.dt": dt,
                      "friction.coupling": "converged"})


def energy_scene(shaft_angle_deg: float, revolutions: int,
                 steps_per_revolution: int | None = None) -> Scene:
    """The paper's frictionless joint spinning free: torque drive of 0 N m from 2000 rpm, no
    load, gravity on; ``steps_per_revolution`` at the initial speed (None: the automatic step)."""
    w0 = ENERGY_SPEED_RPM * math.pi / 30.0
    changes: dict[str, Any] = {"load.torque": 0.0, "revolutions": float(revolutions),
                               "record.timeseries": False}
    if steps_per_revolution is not None:
        changes["numerics.dt"] = 2.0 * math.pi / w0 / steps_per_revolution
    base = named_scene(f"paper-literal-{shaft_angle_deg:g}deg-frictionless")
    scene = replace(base, drive={"kind": "torque", "torque": 0.0, "initial_speed": w0}, **changes)
    return replace(scene, name=f"free-{shaft_angle_deg:g}deg-{ENERGY_SPEED_RPM:g}rpm")


def automatic_steps(shaft_angle_deg: float) -> int:
    """Steps per revolution of the engine's automatic step for the free-spinning scene (default
    ``numerics.accuracy``; at the initial speed)."""
    scene = energy_scene(shaft_angle_deg, 1)
    return round(2.0 * math.pi / scene.drive.max_speed() / choose_step(scene)[0])


def energy_plan(plan: LongRunPlan, shaft_angle_deg: float) -> list[tuple[int | None, float]]:
    """(steps per revolution or None for the automatic step, spectral radius) of the Exudyn
    cases at a shaft angle [deg]: the default settings (the engine's automatic step at the
    default accuracy and spectral radius), the step ladder, the spectral-radius ladder; each
    (steps, rho) once: a ladder rung at the automatic step count is the default case itself
    (at the default accuracy of 1e-3 the automatic step is the floor of 100 steps per revolution
    at both angles, the ladder's first rung)."""
    cases: list[tuple[int | None, float]] = [(None, DEFAULT_RHO)]
    taken = {(automatic_steps(shaft_angle_deg), DEFAULT_RHO)}
    for case in ([(n, DEFAULT_RHO) for n in plan.step_ladder]
                 + [(RHO_LADDER_STEPS, rho) for rho in plan.rho_ladder]):
        if case not in taken:
            cases.append(case)
            taken.add(case)
    return cases


def case_label(engine_name: str, shaft_angle_deg: float, steps: int | None = None,
               rho: float | None = None) -> str:
    """The energy case's name in tables and figures."""
    if engine_name == REFERENCE:
        return f"reference {shaft_angle_deg:g} deg"
    return f"exudyn {shaft_angle_deg:g} deg, {steps or 'auto'} steps/rev, rho {rho:g}"


def model_loss(angle: float, rho: float, steps_per_revolution: float) -> float:
    """Relative energy lost per revolution predicted by :data:`DISSIPATION_MODEL`.

    Parameters
    ----------
    angle : float
        Shaft angle [deg], a key of :data:`DISSIPATION_MODEL`.
    rho : float
        Spectral radius of generalized-alpha.
    steps_per_revolution : float
        Steps per input revolution at the mean speed.
    """
    return DISSIPATION_MODEL[angle] * damping_coefficient(rho) * (2 * math.pi / steps_per_revolution) ** 3


def settings(plan: LongRunPlan) -> dict[str, Any]:
    """The settings of a variant as the summary records them."""
    return {
        "quick": plan.quick,
        "variant": plan.name,
        "drift_scene": DRIFT_SCENE,
        "drift_revolutions": plan.drift_revolutions,
        "drift_node_types": list(plan.node_types),
        "drift_steps_per_revolution": DRIFT_STEPS_PER_REVOLUTION,
        "drift_dt_s": drift_scene(1).numerics.dt,
        "drift_dt_choice": ("given: the automatic step of Rxyz nodes at 10 deg for a speed-ratio "
                            "error of 1e-5, the same for every node type"),
        "spectral_radius": DEFAULT_RHO,
        "friction_coupling": "converged",
        "startup_revolutions_excluded": STARTUP_REVOLUTIONS,
        "energy_revolutions": plan.energy_revolutions,
        "energy_shaft_angles_deg": list(plan.energy_angles),
        "energy_speed_rpm": ENERGY_SPEED_RPM,
        "reference_revolutions": plan.reference_revolutions,
        "dissipation_model_K": {f"{k:g}": v for k, v in DISSIPATION_MODEL.items()},
    }
