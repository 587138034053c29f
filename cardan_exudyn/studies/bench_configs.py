"""What ``cardan bench`` runs: its fixed scenes and every engine configuration on its ladder of
steps per revolution (:func:`configurations`).

Exudyn: the engine's defaults and the "tuned" Newton settings, with the velocity projection
(frictionless scenes), the paper's lagged friction coupling (friction scenes) and the other node
types (full bench); MuJoCo: RK4 at two constraint time constants (frictionless scenes only, when
the optional extra is installed); the reference engine: its quadrature tolerance and table
samples.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from dataclasses import replace as dc_replace
from typing import Any

from cardan_exudyn import engines
from cardan_exudyn.model.options import NODE_TYPES, ExudynOptions
from reference.engine import ReferenceOptions
from reference.scene import Scene, replace
from reference.schema import Result

__all__ = ["SCENES", "ENGINE_NAMES", "EXUDYN_DEFAULT", "EXUDYN_TUNED", "FULL_LADDER",
           "QUICK_LADDER", "BenchError", "Progress", "quiet", "Config", "exudyn_settings",
           "configurations", "simulated_time"]

SCENES = {
    "frictionless-10deg": "paper-literal-10deg-frictionless",
    "frictionless-35deg": "paper-literal-35deg-frictionless",
    "friction-10deg": "paper-literal-10deg",
    "friction-35deg": "paper-literal-35deg",
}
"""The fixed scene set: key -> named scene (all at 2000 rpm, the paper's masses, load and gravity)."""

ENGINE_NAMES = ("exudyn", "mujoco", "reference")
"""The engines the bench compares (keys of :data:`cardan_exudyn.engines.ENGINES`), in its order."""

# "tuned": modified Newton with one Jacobian per step and a relative Newton tolerance of 1e-8
# (the speed-ratio and efficiency errors do not change: the bench shows it); "default": the
# engine's defaults (full Newton, 1e-10).
EXUDYN_DEFAULT = ExudynOptions()
EXUDYN_TUNED = ExudynOptions(modified_newton=True, jacobian_every_step=True,
                             newton_relative_tolerance=1e-8)

# Steps (Exudyn, MuJoCo) or table samples (reference) per input revolution.
FULL_LADDER = {"exudyn": (25, 50, 100, 200, 400, 800, 1600), "mujoco": (20, 25, 30, 40, 60, 100, 200),
               "reference": (36, 360)}
QUICK_LADDER = {"exudyn": (50, 200, 800), "mujoco": (25, 60), "reference": (36,)}

Progress = Callable[[str], None]
"""A progress callback: called with one line of text per finished piece of work."""


def quiet(text: str) -> None:
    """The progress callback that shows nothing."""


class BenchError(ValueError):
    """Bad bench input (unknown scene key, engine, bad repeats)."""


@dataclass(frozen=True)
class Config:
    """One engine configuration at one resolution.

    Attributes
    ----------
    engine : str
        A key of :data:`cardan_exudyn.engines.ENGINES`.
    label : str
        The configuration's name in the tables and plots.
    steps : int
        Steps (Exudyn, MuJoCo) or table samples (reference) per input revolution [-].
    options : engine options or None
        Options of the engine's class; None takes the engine's defaults.
    coupling : str or None
        Friction coupling the scene is switched to (None: the scene's).
    sets_step : bool
        True: ``steps`` sets the scene's time step; False: the options hold the resolution (the
        reference engine's table samples).
    """

    engine: str
    label: str
    steps: int
    options: Any = None
    coupling: str | None = None
    sets_step: bool = True

    def scene(self, base: Scene) -> Scene:
        """``base`` at this configuration's step and friction coupling."""
        changes: dict[str, Any] = {}
        if self.sets_step:
            changes["numerics.dt"] = 2.0 * math.pi / base.drive.max_speed() / self.steps
        if self.coupling is not None:
            changes["friction.coupling"] = self.coupling
        return replace(base, **changes) if changes else base

    def run(self, scene: Scene) -> Result:
        """Run ``scene`` (made by :meth:`scene`) with this configuration's engine and options."""
        return engines.run(scene, self.engine, self.options)

    def describe(self) -> dict[str, Any]:
        """The configuration as a record: engine, label, steps, coupling and options."""
        options = self.options
        if options is not None:
            options = {name: getattr(options, name) for name in options.__dataclass_fields__}
        return {"engine": self.engine, "config": self.label, "steps_per_revolution": self.steps,
                "coupling": self.coupling, "options": options}


def exudyn_settings(friction: bool, quick: bool) -> list[tuple[str, ExudynOptions, str | None]]:
    """``(label, options, coupling)`` of the Exudyn configurations for a scene kind."""
    out = [("exudyn default", EXUDYN_DEFAULT, None), ("exudyn tuned", EXUDYN_TUNED, None)]
    if friction:
        out.append(("exudyn tuned lagged", EXUDYN_TUNED, "lagged"))
    else:
        out.append(("exudyn tuned + projection", dc_replace(EXUDYN_TUNED, velocity_projection=True),
                    None))
    if not quick:
        out += [(f"exudyn tuned {node}", dc_replace(EXUDYN_TUNED, node_type=node), None)
                for node in NODE_TYPES[1:]]
    return out


def exudyn_configs(friction: bool, quick: bool, ladder: dict[str, tuple[int, ...]]) -> list[Config]:
    """Every Exudyn setting on the ladder (quick: the tuned one only on all of it)."""
    out = []
    for label, options, coupling in exudyn_settings(friction, quick):
        steps = ladder["exudyn"]
        if quick and label != "exudyn tuned":
            steps = steps[:2]
        out += [Config("exudyn", label, n, options, coupling) for n in steps]
    return out


def mujoco_configs(quick: bool, ladder: dict[str, tuple[int, ...]]) -> list[Config]:
    """MuJoCo, RK4, constraint time constants 10 and 20 (recommended) steps on the ladder."""
    out = []
    for tc in ((10.0,) if quick else (10.0, 20.0)):
        try:
            options = engines.make_options("mujoco", timeconst_steps=tc)
        except engines.EngineUnavailable:  # MuJoCo is an optional extra: its rows are left out
            return []
        label = f"mujoco RK4 tc {tc:g} dt" + (" (recommended)" if tc == 20.0 else "")
        out += [Config("mujoco", label, n, options) for n in ladder["mujoco"]]
    return out


def reference_configs(quick: bool, ladder: dict[str, tuple[int, ...]]) -> list[Config]:
    """The reference engine at quadrature tolerances 1e-9, 1e-6, 1e-4 and its table samples."""
    return [Config("reference", f"reference rtol {rtol:g}", n,
                   ReferenceOptions(samples_per_revolution=n, quadrature_rtol=rtol), sets_step=False)
            for rtol in ((1e-6,) if quick else (1e-9, 1e-6, 1e-4)) for n in ladder["reference"]]


def configurations(scene_key: str, quick: bool = False,
                   engines: Iterable[str] = ENGINE_NAMES) -> list[Config]:
    """Every configuration benchmarked on the scene ``scene_key`` of :data:`SCENES`.

    MuJoCo runs the frictionless scenes only (it has no friction proportional to the reactions).
    """
    engines = set(engines)
    ladder = QUICK_LADDER if quick else FULL_LADDER
    friction = scene_key.startswith("friction-")
    out: list[Config] = []
    if "exudyn" in engines:
        out += exudyn_configs(friction, quick, ladder)
    if "mujoco" in engines and not friction:
        out += mujoco_configs(quick, ladder)
    if "reference" in engines:
        out += reference_configs(quick, ladder)
    return out


def simulated_time(scene: Scene) -> float:
    """The time the scene's revolutions take at the drive's highest speed [s]."""
    return 2.0 * math.pi * scene.revolutions / scene.drive.max_speed()
