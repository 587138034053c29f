"""The MuJoCo settings study (``python tests/benchmarks mujoco-settings``): one row per scene and
case with every error measure."""

from __future__ import annotations

import pytest

pytest.importorskip("mujoco")

from benchmarks.mujoco_settings.study import settings_study, study_cases  # noqa: E402

DT = 1e-4


def test_settings_study_table():
    """The study returns one row per scene and case with every error measure."""
    cases = study_cases((DT,))[:3]
    table = settings_study(scenes=("paper-literal-10deg-frictionless",), cases=cases, repeats=1)
    assert list(table["case"]) == [label for label, _ in cases]
    assert {"speed_ratio_error", "torque_in_error", "bearing_drift_m", "wall_time_s"} <= set(table)
