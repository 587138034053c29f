"""The frictionless path's fixed costs cut without changing a result: a model solved again gives
the table of a fresh build, the Richardson run equals the combination of two independent runs,
and the cheaper helpers (finiteness check, row-wise cross product) agree with what they replace."""

from __future__ import annotations

import math

import numpy as np
import pytest

from cardan_exudyn import run
from cardan_exudyn.model import richardson
from cardan_exudyn.model.options import ExudynOptions
from cardan_exudyn.model.postprocess import first_non_finite, postprocess
from cardan_exudyn.model.projection import cross_rows
from cardan_exudyn.model.solve import reusable, run_columns, solve
from reference.paper.scenes import named_scene
from reference.scene.mapping import replace

OPTIONS = ExudynOptions(modified_newton=True, jacobian_every_step=True, newton_relative_tolerance=1e-8,
                        velocity_projection=True)


def _scene(steps_per_revolution: int, name: str = "paper-literal-35deg-frictionless"):
    base = named_scene(name)
    dt = 2.0 * math.pi / base.drive.max_speed() / steps_per_revolution
    return replace(base, **{"numerics.dt": dt, "revolutions": 2.0})


def test_a_model_solved_again_gives_the_table_of_a_fresh_build():
    """The coarse run's model integrated again at half the step: every column equal (bit for bit)
    to those of a model built for the finer step, the whole revolutions of the input included."""
    coarse = solve(_scene(25), OPTIONS, reactions=True)
    postprocess(coarse.model, project=True)
    again = solve(_scene(50), OPTIONS, reactions=True, model=coarse.model)
    fresh = solve(_scene(50), OPTIONS, reactions=True)
    assert again.model is coarse.model
    cols_again = postprocess(again.model, project=True)
    cols_fresh = postprocess(fresh.model, project=True)
    assert cols_again.keys() == cols_fresh.keys()
    for key, values in cols_fresh.items():
        assert np.array_equal(cols_again[key], values, equal_nan=True), key
    assert again.model.input_turns.counts == fresh.model.input_turns.counts


def test_a_model_with_friction_is_not_solved_again():
    """The friction coupling keeps one run's state: such a model is built anew, never reused."""
    scene = replace(_scene(25, "paper-literal-10deg"), **{"revolutions": 1.0})
    solved = solve(scene, OPTIONS, reactions=False)
    assert not reusable(solved.model, reactions=False)
    with pytest.raises(ValueError, match="cannot be solved again"):
        solve(scene, OPTIONS, reactions=False, model=solved.model)


def test_richardson_run_equals_the_combination_of_two_fresh_runs():
    """``numerics.richardson`` (one build, solved twice; no per-run means) gives the table and means
    of two independent runs at h and h/2 combined by :func:`richardson.combine`."""
    scene = _scene(25)
    result = run(replace(scene, **{"numerics.richardson": True}), options=OPTIONS)
    _, coarse, origin = run_columns(scene, OPTIONS)
    fine_summary, fine, _ = run_columns(replace(scene, **{"numerics.dt": 0.5 * scene.numerics.dt}), OPTIONS)
    combined = richardson.combine(coarse, fine)
    for key, values in combined.items():
        expected = values + origin if key == "t" else values
        assert np.array_equal(result.table[key].to_numpy(), expected, equal_nan=True), key
    means = fine_summary.whole_revolution_means(combined, scene.record.skip_revolutions)
    assert result.summary.mean_torque_in == means["mean_torque_in"]


def test_first_non_finite_names_the_first_bad_column():
    """All finite: None; otherwise the first column in order with a NaN or inf (``efficiency``,
    which is NaN where no power flows in, is not checked)."""
    cols = {"t": np.arange(3.0), "efficiency": np.array([np.nan, 1.0, 1.0]), "a": np.ones(3)}
    assert first_non_finite(cols) is None
    cols["b"] = np.array([1.0, np.inf, 0.0])
    cols["c"] = np.array([np.nan, 0.0, 0.0])
    assert first_non_finite(cols) == "b"
    assert first_non_finite({}) is None


def test_cross_rows_is_numpys_cross_product():
    """Row by row, and with one side a single vector: the same values as ``np.cross``."""
    rng = np.random.default_rng(1)
    a, b, v = rng.normal(size=(7, 3)), rng.normal(size=(7, 3)), rng.normal(size=3)
    assert np.array_equal(cross_rows(a, b), np.cross(a, b))
    assert np.array_equal(cross_rows(v, b), np.cross(v, b))
    assert np.array_equal(cross_rows(a, v), np.cross(a, v))
