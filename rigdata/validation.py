"""Measured against computed efficiency for one record: the measurement, each engine driven by it,
and the difference with its standard uncertainty (the output transducer's error enters both sides,
propagated as correlated) and significance at k = 2 and by Monte Carlo.
"""

from __future__ import annotations

import math
import os
import warnings
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from cardan_exudyn.engines import EngineUnavailable, get_engine, run
from cardan_exudyn.jsonable import to_jsonable
from reference.paper.scenes import named_scene
from reference.results.summary import Status
from reference.scene.files import load_scene
from reference.scene.scene import Scene
from rigdata.checks import Finding, RigDataWarning, shaft_angle_agrees
from rigdata.conditioning import Conditioned, Conditioning, condition
from rigdata.efficiency import SQRT3, Measured, measured_efficiency, transducer_pair
from rigdata.measurement import Source, as_record, measurement_findings
from rigdata.model import computed_efficiency, measured_scene, model_sensitivities
from rigdata.montecarlo import check_draws
from rigdata.record import RigRecord, with_signs
from rigdata.reproduce import model_settings, scene_entry
from rigdata.transducer import PROVENANCE, Transducer

__all__ = ["K", "MODEL_ENGINES", "CONSTANT_OUTPUT_ERRORS", "Validation", "as_scene", "compare",
           "check_engines", "accuracy_needed", "validate"]

#: Engines that take the measured angle drive and load history (MuJoCo takes constant loads only).
MODEL_ENGINES = ("reference", "exudyn")
K = 2.0
"""Coverage factor of the significance test."""
#: Budget rows that are a constant error of the output torque, which the model's load shares.
CONSTANT_OUTPUT_ERRORS = ("accuracy class, output torque", "resolution (acquisition step), output torque")


def as_scene(scene: Scene | str | os.PathLike) -> Scene:
    """``scene`` itself, a scene TOML file, else a named scene; SceneError naming what is wrong."""
    if isinstance(scene, Scene):
        return scene
    if not isinstance(scene, (str, os.PathLike)):
        raise TypeError(f"`scene` must be a Scene, a scene name or a scene file, got {scene!r}")
    path = Path(scene)
    if isinstance(scene, os.PathLike) or path.suffix.lower() == ".toml" or path.is_file():
        return load_scene(path)
    return named_scene(scene)


def compare(measured: Measured, computed: Mapping[str, Any], sensitivities: Mapping[str, float]) -> dict:
    """Difference measured - computed [-], its standard uncertainty and significance (k = 2).

    The output transducer's constant errors move measured and computed (through the load) efficiency,
    so the difference sees ``c_meas - c_model``; the drift is left uncorrelated (below 1e-3 of the
    variance). The yoke phase's half-turn ambiguity is rectangular of half width |difference| / 2.
    Keys: ``engine``, ``computed_efficiency``, ``difference``, ``difference_u``, ``expanded_u``,
    ``significant_k2``; with draws ``difference_interval_95_mc``, ``significant_mc``.
    """
    eta_model = computed["mean_efficiency"]
    d = measured.efficiency - eta_model
    terms = []
    for row in measured.budget:
        c = row["sensitivity"]
        if row["quantity"] in CONSTANT_OUTPUT_ERRORS:  # the model's load carries them too
            c = c - sensitivities["load"]
        terms.append(c * row["standard_uncertainty"])
    terms.append(0.5 * abs(sensitivities["phase_ambiguity"]) / SQRT3)
    u = math.sqrt(sum(x * x for x in terms))
    out = {"engine": computed["engine"], "computed_efficiency": eta_model, "difference": d,
           "difference_u": u, "expanded_u": K * u, "significant_k2": bool(abs(d) > K * u)}
    draws = measured.draws
    if draws:
        diffs = draws["efficiency"] - (eta_model + sensitivities["load"] * draws["offset_out"])
        lo, hi = np.percentile(diffs, [2.5, 97.5])
        # the draws spread the measurement around its value; the difference is significant when
        # zero is outside the 95 % interval of the difference they give
        out["difference_interval_95_mc"] = [float(lo), float(hi)]
        out["significant_mc"] = bool(not (lo <= 0.0 <= hi))
    return out


def accuracy_needed(measured: Measured, target_u: float = 0.01) -> float:
    """Accuracy class [-] the torque transducers need for efficiency uncertainty ``target_u`` [-] from the
    class alone (NaN if it contributes nothing).
    """
    acc = [b["contribution"] for b in measured.budget if b["quantity"].startswith("accuracy class")]
    total = math.sqrt(sum(a * a for a in acc))
    cls = measured.summary["transducer_in"]["accuracy_class"]
    return cls * target_u / total if total > 0 else float("nan")


@dataclass(frozen=True)
class Validation:
    """Measured against computed efficiency for one record (what ``cardan rig validate`` reports).

    Attributes
    ----------
    record : RigRecord
    conditioned : Conditioned
    measured : Measured
    scene : Scene
        The joint driven and loaded by the measurement.
    computed : dict of str to dict
        Per engine, :func:`rigdata.model.computed_efficiency`.
    comparisons : dict of str to dict
        Per engine that ran ``ok``, :func:`compare`.
    sensitivities : dict
        :func:`rigdata.model.model_sensitivities`; empty when no engine ran ``ok``.
    transducers : tuple of Transducer
    findings : tuple of Finding
        The measurement's checks and the shaft angle's (:mod:`rigdata.checks`).
    """

    record: RigRecord
    conditioned: Conditioned
    measured: Measured
    scene: Scene
    computed: dict[str, dict[str, Any]]
    comparisons: dict[str, dict[str, Any]]
    sensitivities: dict[str, float]
    transducers: tuple[Transducer, Transducer]
    findings: tuple[Finding, ...] = ()

    @property
    def measurement_usable(self) -> bool:
        """False when the measurement is ``unphysical`` or ``inconsistent`` (an error in the data); an
        ``unresolved`` efficiency or a shaft angle ``mismatch`` is reported, the comparison stands.
        """
        return not any(f.status in ("unphysical", "inconsistent") for f in self.findings)

    @property
    def measured_efficiency(self) -> float:
        """Measured ``W_out / W_in`` over the window [-]."""
        return self.measured.efficiency

    @property
    def computed_efficiency(self) -> dict[str, float | None]:
        """Each engine's mean efficiency over the same revolutions [-] (None unless ``ok``)."""
        return {engine: comp["mean_efficiency"] for engine, comp in self.computed.items()}

    @property
    def success(self) -> bool:
        """True when every engine ran ``ok``."""
        return all(comp["status"] == Status.OK for comp in self.computed.values())

    def as_dict(self) -> dict[str, Any]:
        """JSON summary (``validation.json``): file and its SHA-256, provenance, conditioning, measured and
        computed efficiencies, comparisons, sensitivities, assumptions; the model ``scene`` run
        (:func:`rigdata.reproduce.scene_entry`) and its ``model`` shaft angle and friction.
        """
        rec = self.record
        cond = self.conditioned
        meas = self.measured
        out = {
            "file": str(rec.file), "file_sha256": rec.provenance.get("sha256"),
            "status": next((f.status for f in self.findings if not f.ok), "ok"),
            "checks": [f.as_dict() for f in self.findings],
            "provenance": {k: val for k, val in rec.provenance.items()
                                                  if k not in ("header", "synthetic")},
            "synthetic": rec.provenance.get("synthetic"), "sample_rate": rec.sample_rate,
            "duration_s": rec.duration,
            "conditioning": {**cond.settings, "cutoff_hz": cond.cutoff, "window_s": list(cond.window),
                             "revolutions": cond.revolutions, "phase": cond.phase,
                             "phase_deg": math.degrees(cond.phase), "phase_fit": cond.phase_fit},
            **meas.as_dict(),
            "computed": {engine: {k: val for k, val in comp.items() if k != "series"}
                         for engine, comp in self.computed.items()},
            "comparisons": self.comparisons,
            "model_sensitivities": self.sensitivities,
            "accuracy_class_for_u_0.01": accuracy_needed(meas),
            "assumptions": PROVENANCE,
            "model": model_settings(self.scene), "scene": scene_entry(self.scene),
        }
        return to_jsonable(out)


def _ok_efficiency(computed: Mapping[str, Any] | None) -> float | None:
    """Mean efficiency of a computed run that ended ``ok``, else None."""
    if computed is None or computed["status"] != Status.OK:
        return None
    return float(computed["mean_efficiency"])


def validate(source: Source, scene: Scene | str | os.PathLike = "rig",
             engines: tuple[str, ...] = MODEL_ENGINES, *, conditioning: Conditioning | None = None,
             transducers: Transducer | tuple[Transducer, Transducer] | None = None,
             monte_carlo: int = 2000, seed: int = 0, progress: Callable[[str], None] | None = None,
             signs: dict[str, int] | None = None, **read_options: Any) -> Validation:
    """Measured against computed efficiency for one record; nothing is written (see :func:`write_report`).

    Parameters
    ----------
    source : RigRecord, str or path-like
        A record or a rig file (read with ``read_options``, :func:`rigdata.readers.read`).
    scene : Scene, str or path-like
        Joint, shaft angle, friction and numerics (drive and load replaced): scene, TOML file or name.
    engines : tuple of str
        Engines taking angle drives and load histories (:data:`MODEL_ENGINES`).
    conditioning, transducers, monte_carlo, seed
        As for :func:`rigdata.measurement.measure`.
    progress : callable(str), optional
        Called with a line before each long step.
    signs : dict of str to int, optional
        As for :func:`rigdata.measurement.measure`.

    Warns
    -----
    RigDataWarning
        Before the model runs, when the recording's own shaft angle differs from the scene's beyond
        twice its uncertainty.

    Raises
    ------
    RigDataError
        A file or record that cannot be measured.
    EngineUnavailable
        An unknown or not installed engine.
    """
    say = progress or (lambda line: None)
    if isinstance(engines, (str, bytes)):
        raise TypeError(f"`engines` must be a sequence of engine names such as ('reference', 'exudyn'), not "
                        f"one string: got {engines!r:.80}")
    check_draws(monte_carlo, seed)
    base = as_scene(scene)
    check_engines(engines)  # now, not after the measurement
    record = with_signs(as_record(source, **read_options), signs)
    pair = transducer_pair(transducers)
    say("conditioning")
    cond = condition(record, base.joint.geometry.shaft_angle, conditioning)
    say("measured efficiency and its uncertainty")
    measured = measured_efficiency(cond, pair, monte_carlo=monte_carlo, seed=seed)
    findings = (*measurement_findings(cond, measured, pair, record.file),
                shaft_angle_agrees(cond, base.joint.geometry.shaft_angle))
    if not findings[-1].ok:
        warnings.warn(findings[-1].message, RigDataWarning, stacklevel=2)
    model = measured_scene(cond, base)
    computed, comparisons, sens = _run_models(cond, base, model, engines, measured, pair, say)
    return Validation(record, cond, measured, model, computed, comparisons, sens, pair, findings)


def check_engines(engines: tuple[str, ...]) -> None:
    """:class:`EngineUnavailable` for an engine unknown, not installed, or unable to take a measured drive and
    load.
    """
    for engine in engines:
        if engine not in MODEL_ENGINES:
            get_engine(engine)  # unknown or not installed: its own message
            raise EngineUnavailable(f"engine {engine!r} cannot be driven by a measurement (angle "
                                    f"and load histories): use {' and/or '.join(MODEL_ENGINES)}")


def _run_models(cond: Conditioned, base: Scene, model: Scene, engines: tuple[str, ...], measured: Measured,
                pair: tuple[Transducer, Transducer], say: Callable[[str], None]) -> tuple[dict, dict, dict]:
    """Each engine on scene ``model``: computed efficiency, comparison if ``ok``, and sensitivities (first
    ``ok`` engine).
    """
    computed: dict[str, dict[str, Any]] = {}
    comparisons: dict[str, dict[str, Any]] = {}
    sens = None
    for engine in engines:
        say(f"model driven by the measurement: {engine}")
        computed[engine] = computed_efficiency(run(model, engine))
        if computed[engine]["status"] != Status.OK:
            continue
        if sens is None:
            say("model sensitivities (load offset, yoke half turn)")
            # the load offset's standard uncertainty as the differencing step; with accuracy
            # class 0 it is zero and any finite step gives the (then unused) sensitivity
            step = pair[1].accuracy_limit / SQRT3 or 1e-3 * pair[1].full_scale
            sens = model_sensitivities(cond, base, step, _ok_efficiency(computed.get("reference")))
        comparisons[engine] = compare(measured, computed[engine], sens)
    return computed, comparisons, sens or {}
