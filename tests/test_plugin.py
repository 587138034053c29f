"""The pytest plugin (``cardan_exudyn.testing``), tested as a user meets it: a throw-away test
project run by pytest's own ``pytester``, with the plugin loaded through its ``pytest11`` entry
point. Small scenes (one revolution, the reference engine where the engine does not matter) keep
the file fast."""

from __future__ import annotations

import re
from dataclasses import replace as dataclass_replace
from pathlib import Path

import pytest

import cardan_exudyn.testing.plugin  # noqa: F401 (imported here: see below)
from cardan_exudyn.engines import get_engine, make_options
from cardan_exudyn.model.error_estimate import SAFETY_FACTOR, AccuracyError, error_estimate
from cardan_exudyn.testing import CachingRunner, assert_efficiency, assert_engines_agree, make_scene
from cardan_exudyn.testing.assertions import MAX_RELATIVE_ERROR, Limit, tolerance
from reference.results.result import Result
from reference.results.summary import Status, Summary
from reference.scene.mapping import scene_to_dict
from reference.scene.validation import SceneError

pytest_plugins = ["pytester"]

# pytester's in-process runs forget the modules they import, and pytest rewrites the asserts of
# the installed plugin's distribution on every import: the engines and the plugin are imported
# once here, so that each run of a throw-away project does not import them again.
get_engine("exudyn"), get_engine("reference")

DOCS = Path(__file__).resolve().parents[1] / "docs" / "pytest.md"
SMALL = "paper-literal-10deg-frictionless"


def run_project(pytester: pytest.Pytester, source: str, *args: str) -> pytest.RunResult:
    """``source`` as the project's one test module, run in this process."""
    pytester.makepyfile(test_project=source)
    return pytester.runpytest("-p", "no:cacheprovider", "-p", "no:hypothesispytest", *args)


def test_the_entry_point_loads_the_plugin(pytester):
    """Installed, the plugin is there without a conftest: options, marker, fixtures."""
    result = pytester.runpytest("-p", "no:hypothesispytest", "--help")
    result.stdout.fnmatch_lines(["*cardan-exudyn*", "*--cardan-skip-slow*", "*--cardan-no-cache*",
                                 "*--cardan-runs*"])
    result = pytester.runpytest("-p", "no:hypothesispytest", "--markers")
    result.stdout.fnmatch_lines(["@pytest.mark.cardan_slow:*--cardan-skip-slow*"])
    result = pytester.runpytest("-p", "no:hypothesispytest", "--fixtures")
    result.stdout.fnmatch_lines(["cardan_scene*", "*factory of scenes*", "cardan_run*"])
    result = pytester.runpytest("-p", "no:hypothesispytest", "-p", "no:cardan_exudyn", "--help")
    result.stdout.no_fnmatch_line("*--cardan-*")


def test_the_marker_passes_strict_markers_and_skips_on_request(pytester):
    source = """
        import pytest

        @pytest.mark.cardan_slow
        def test_slow():
            pass

        def test_fast():
            pass
    """
    run_project(pytester, source, "--strict-markers").assert_outcomes(passed=2)
    result = run_project(pytester, source, "--strict-markers", "--cardan-skip-slow", "-rs")
    result.assert_outcomes(passed=1, skipped=1)
    result.stdout.fnmatch_lines(["*cardan_slow: skipped by --cardan-skip-slow*"])


def test_cardan_scene_builds_named_and_file_scenes(pytester):
    pytester.makefile(".toml", joint=f'base = "{SMALL}"\nrevolutions = 1.5\n')
    source = f"""
        import math
        from reference.scene.scene import Scene

        def test_named(cardan_scene):
            scene = cardan_scene("{SMALL}", revolutions=1.0, numerics__accuracy=1e-4,
                                 **{{"joint.geometry.shaft_angle_deg": 20.0}})
            assert isinstance(scene, Scene)
            assert scene.revolutions == 1.0 and scene.numerics.accuracy == 1e-4
            assert math.isclose(math.degrees(scene.joint.geometry.shaft_angle), 20.0)

        def test_file(cardan_scene):
            assert cardan_scene("joint.toml").revolutions == 1.5

        def test_scene_and_changes(cardan_scene):
            scene = cardan_scene(cardan_scene("{SMALL}"), revolutions=3.0)
            assert scene.revolutions == 3.0

        def test_bad_name(cardan_scene):
            cardan_scene("paper-99")

        def test_bad_value(cardan_scene):
            cardan_scene("{SMALL}", revolutions=-1.0)
    """
    result = run_project(pytester, source)
    result.assert_outcomes(passed=3, failed=2)
    result.stdout.fnmatch_lines(["*cardan_scene: scene 'paper-99': unknown scene name 'paper-99'*",
                                 "*cardan_scene: scene*`revolutions` must be positive*"])
    result.stdout.no_fnmatch_line("*make_scene*")  # one line, no traceback into the plugin
    result.stdout.no_fnmatch_line("*During handling of the above exception*")


def test_cardan_run_computes_each_run_once_and_hands_out_copies(pytester):
    source = f"""
        from cardan_exudyn.engines import make_options

        def test_first(cardan_scene, cardan_run):
            result = cardan_run(cardan_scene("{SMALL}", revolutions=1.0), "reference")
            assert result.success
            result.summary.mean_efficiency = -1.0  # a test changing its copy
            del result.table["torque_in"]

        def test_second(cardan_scene, cardan_run):
            scene = cardan_scene("{SMALL}", revolutions=1.0)  # built again: the same key
            result = cardan_run(scene, "reference")
            assert result.mean_efficiency == 1.0 and "torque_in" in result.table
            same = cardan_run(scene, options=make_options("reference"))
            assert same is not result
            assert cardan_run.runs == 1 and cardan_run.reused == 2
    """
    result = run_project(pytester, source, "--cardan-runs")
    result.assert_outcomes(passed=2)
    result.stdout.fnmatch_lines(["*cardan-exudyn engine runs*",
                                 "| paper-literal-10deg-*-frictionless | 1 | reference |*| ok "
                                 "| 1.000000 |*| 2 |",
                                 "1 engine run(s), 2 result(s) reused from the cache"])
    result = run_project(pytester, source.replace("runs == 1 and cardan_run.reused == 2",
                                                  "runs == 3 and cardan_run.reused == 0"),
                         "--cardan-no-cache")
    result.assert_outcomes(passed=2)


def test_assert_efficiency_passes_and_fails_readably(pytester):
    source = """
        import pytest
        from cardan_exudyn.testing import assert_efficiency

        @pytest.fixture(scope="module")
        def runs(cardan_scene, cardan_run):
            scene = cardan_scene("rig-literal", revolutions=1.0, numerics__accuracy=3e-4)
            return cardan_run(scene), cardan_run(scene, "reference")

        def test_exudyn_agrees_with_the_reference_within_its_estimate(runs, cardan_run):
            exudyn, reference = runs
            assert_efficiency(exudyn, reference.mean_efficiency, run=cardan_run)

        def test_an_explicit_tolerance(runs, cardan_run):
            assert_efficiency(runs[0], runs[1].mean_efficiency, rtol=3e-3, run=cardan_run)

        def test_too_tight_a_tolerance_fails(runs, cardan_run):
            assert_efficiency(runs[0], runs[0].mean_efficiency, atol=1e-12, run=cardan_run)

        def test_wrong_value(runs, cardan_run):
            assert_efficiency(runs[0], runs[0].mean_efficiency + 0.01, run=cardan_run)

        def test_failed_run(cardan_scene, cardan_run):
            result = cardan_run(cardan_scene("rig-literal-errors", revolutions=1.0), "reference")
            assert_efficiency(result, 0.2)
    """
    result = run_project(pytester, source)
    result.assert_outcomes(passed=2, failed=3)
    result.stdout.fnmatch_lines([
        ">*assert_efficiency(runs?0?, runs?0?.mean_efficiency, atol=1e-12, run=cardan_run)",
        "E*| mean_efficiency | * | * | +0.000e+00 | - | the tolerance asked, 1e-12, is below what the "
        "runs resolve, 5 x estimated error = *: give at least that, *",
    ])
    result.stdout.fnmatch_lines([
        ">*assert_efficiency(runs?0?, runs?0?.mean_efficiency + 0.01, run=cardan_run)",
        "E*AssertionError: mean efficiency of scene 'rig*' (exudyn) is not 0.196*:",
        "E*| quantity | expected | exudyn | difference | tolerance | from |",
        "E*| mean_efficiency | 0.196* | 0.186* | -1.000e-02 | *e-0* | 5 x estimated error |",
        "E*error estimates: exudyn: step halving: dt = * s and * s, order 2*",
    ])
    result.stdout.fnmatch_lines([
        "E*AssertionError: the reference run of scene 'rig-literal-errors' ended self_locking: friction "
        "self-locks*: no mean efficiency to compare with 0.2"])
    assert "make_scene" not in result.stdout.str() and "def tolerance" not in result.stdout.str()


def test_assert_engines_agree_passes_and_fails_with_a_table(pytester):
    source = f"""
        from cardan_exudyn.testing import assert_engines_agree

        def test_agree(cardan_scene, cardan_run):
            scene = cardan_scene("{SMALL}", revolutions=1.0)
            assert_engines_agree(scene, columns=["mean_efficiency", "work_ratio", "omega_out",
                                                 "theta_out"], run=cardan_run)

        def test_disagree(cardan_scene, cardan_run):
            def doctored(scene, engine, options):  # a reference engine 0.1 % off
                result = cardan_run(scene, engine, options)
                if result.summary.engine == "reference":
                    result.summary.work_ratio *= 1.001
                    result.table["omega_out"] *= 1.001
                return result

            scene = cardan_scene("{SMALL}", revolutions=1.0)
            assert_engines_agree(scene, columns=["mean_efficiency", "work_ratio", "omega_out"],
                                 run=doctored)

        def test_failed_run(cardan_scene, cardan_run):
            scene = cardan_scene("rig-literal-errors", revolutions=1.0)
            assert_engines_agree(scene, run=cardan_run)
    """
    result = run_project(pytester, source)
    result.assert_outcomes(passed=1, failed=2)
    result.stdout.fnmatch_lines([
        "E*AssertionError: engine reference disagrees with engine exudyn on scene 'paper-literal-10deg*':",
        "E*| quantity | exudyn | reference | difference | tolerance | from |",
        "E*| work_ratio | 0.999* | 1.00* | +1.*e-03 | *e-0* | 5 x estimated error |",
        "E*| omega_out (largest difference) | * | * | +2.1*e-01 | *e-0* | 5 x estimated error |",
        "E*error estimates: exudyn: step halving*; reference: quadrature*",
    ])
    assert "| mean_efficiency |" not in result.stdout.str()  # agrees: not in the table
    result.stdout.fnmatch_lines(["E*AssertionError: the exudyn run of scene 'rig-literal-errors' ended "
                                 "self_locking*", "E*the reference run of scene 'rig-literal-errors' "
                                                  "ended self_locking*"])


def fake_result(scene, engine, options) -> Result:
    return Result(None, Summary(Status.OK, engine=engine, mean_efficiency=0.5, wall_time_s=0.0))


class Counting:
    """A run function that counts its calls."""

    def __init__(self) -> None:
        self.calls = []

    def __call__(self, scene, engine, options) -> Result:
        self.calls.append((scene, engine, options))
        return fake_result(scene, engine, options)


def test_the_cache_key_is_the_scene_engine_and_options_by_value():
    counting = Counting()
    runner = CachingRunner(counting)
    scene = make_scene(SMALL, revolutions=1.0)
    runner(scene)
    runner(make_scene(SMALL, revolutions=1.0))  # equal, not identical
    runner(scene, "exudyn", make_options("exudyn"))  # the default options, given
    runner(scene, spectral_radius=0.6)  # the same, as keywords
    assert len(counting.calls) == 1 and runner.reused == 3
    runner(scene, spectral_radius=0.5)
    runner(scene, "reference")
    runner(make_scene(SMALL, revolutions=1.0, numerics__accuracy=1e-6))
    runner(dataclass_replace(scene, name="renamed"))
    assert len(counting.calls) == 5 and runner.runs == 5
    assert [r.engine for r in runner.records] == ["exudyn", "exudyn", "reference", "exudyn", "exudyn"]


def test_cached_results_are_copies():
    runner = CachingRunner(Counting())
    scene = make_scene(SMALL, revolutions=1.0)
    first = runner(scene)
    first.summary.mean_efficiency = 0.0
    first.summary.extras["mine"] = 1
    second = runner(scene)
    assert second.summary.mean_efficiency == 0.5 and "mine" not in second.summary.extras


def test_bad_calls_raise_and_are_not_cached():
    counting = Counting()
    runner = CachingRunner(counting)
    scene = make_scene(SMALL, revolutions=1.0)
    with pytest.raises(TypeError, match="must be a reference.scene.scene.Scene"):
        runner("paper-literal-10deg")
    with pytest.raises(ValueError, match="not both"):
        runner(scene, options=make_options("exudyn"), node_type="EP")
    with pytest.raises(ValueError, match="not the options of engine 'reference'"):
        runner(scene, "reference", make_options("exudyn"))
    with pytest.raises(ValueError, match="unknown option"):
        runner(scene, no_such_option=1)
    assert counting.calls == [] and runner.runs == 0


def test_make_scene_names_the_source_in_errors(tmp_path):
    with pytest.raises(SceneError, match=r"^scene 'nope\.toml': cannot read scene file"):
        make_scene("nope.toml", root=tmp_path)
    with pytest.raises(SceneError, match="the source must be a scene name"):
        make_scene(3)
    with pytest.raises(SceneError, match=r"^scene 'rig-literal': .*unknown scene field"):
        make_scene("rig-literal", no__such=1)


def summary_of(scene, engine: str, dt: float, efficiency: float) -> Summary:
    return Summary(Status.OK, engine=engine, scene=scene_to_dict(scene), dt=dt,
                   input_work=10.0, loss_work=10.0 * (1.0 - efficiency), mean_efficiency=efficiency)


@pytest.mark.parametrize(("coupling", "band", "factor"), [
    ("converged", 0.5, 4.0 / 3.0),   # sign ramps resolved by the 0.06 rad step: second order
    ("converged", None, 4.0 / 3.0),  # narrow ramps too: the jumps are integrated across
    ("lagged", 0.5, 2.0)])           # friction lags one step: first order
def test_step_halving_reruns_at_half_the_step(coupling, band, factor):
    scene = make_scene("rig-literal", revolutions=1.0, friction__coupling=coupling,
                       friction__sign_band_relative=band, record__timeseries=False)
    reruns = []

    def half_step(scene, engine, options):
        reruns.append((scene, engine, options))
        return Result(None, summary_of(scene, engine, scene.numerics.dt, 0.9001))

    result = Result(None, summary_of(scene, "exudyn", 0.01, 0.9))
    estimate = error_estimate(result, half_step)
    (rerun, engine, options), = reruns
    assert rerun.numerics.dt == 0.005 and engine == "exudyn"
    assert options == make_options("exudyn", error_estimate=False)  # no companion: the run halved
    assert rerun.joint == scene.joint and rerun.friction == scene.friction
    assert estimate.method == "step halving"
    assert estimate.of("mean_efficiency") == pytest.approx(factor * 1e-4)
    assert estimate.of("loss_work") == pytest.approx(factor * 1e-3)


def test_a_failed_half_step_run_is_no_estimate():
    scene = make_scene("rig-literal", revolutions=1.0)

    def locking(scene, engine, options):
        summary = summary_of(scene, engine, scene.numerics.dt, 0.9)
        summary.fail(Status.SELF_LOCKING, "loop gain >= 1")
        return Result(None, summary)

    with pytest.raises(AccuracyError, match=r"half the step \(dt = 0.005 s\) ended self_locking"):
        error_estimate(Result(None, summary_of(scene, "exudyn", 0.01, 0.9)), locking)


def test_an_engine_without_an_estimate():
    scene = make_scene(SMALL, revolutions=1.0)
    assert error_estimate(Result(None, summary_of(scene, "mujoco", 1e-4, 1.0))) is None


@pytest.fixture(scope="module")
def reference_rig() -> Result:
    return CachingRunner()(make_scene("rig-literal", revolutions=1.0), "reference")


def test_the_reference_engine_reports_its_own_error(reference_rig):
    estimate = error_estimate(reference_rig)
    assert estimate.method == "quadrature" and estimate.detail.endswith("table rows exact")
    assert 0 < estimate.of("mean_efficiency") < 1e-9 and estimate.of("omega_out") == 0.0


def test_tolerance_never_passes_by_default_without_an_estimate():
    assert tolerance(1.0, [None, 0.0]) == "no error estimate: give rtol or atol"
    assert tolerance(1.0, [None, 0.0], rtol=1e-3) == Limit(1e-3, 1e-3, None)
    too_large = 2 * MAX_RELATIVE_ERROR / SAFETY_FACTOR
    assert "refine the run" in tolerance(1.0, [too_large, 0.0])
    assert "refine the run" in tolerance(1.0, [too_large, 0.0], atol=1e-6)
    assert tolerance(1.0, [too_large, 0.0], atol=1.0).value == 1.0  # asked for, and larger


def test_an_explicit_tolerance_is_used_as_given():
    """A tolerance the test gives is the limit as given (no rounding floor either); below
    SAFETY_FACTOR times the estimate it is a reason to fail naming both, never widened."""
    limit = tolerance(2.0, [1e-5, 1e-6], rtol=1e-3)
    assert limit.value == 2e-3 and limit.asked == 2e-3 and limit.describe() == "asked"
    assert tolerance(2.0, [0.0, 0.0], atol=0.0).value == 0.0
    too_tight = tolerance(2.0, [1e-5, 1e-6], atol=1e-6)
    assert isinstance(too_tight, str)
    assert re.fullmatch(r"the tolerance asked, 1e-06, is below what the runs resolve, 5 x estimated "
                        r"error = 5.5e-05 \(rtol 2.75e-05\): give at least that, or refine the runs "
                        r"\(numerics.accuracy, dt\)", too_tight)
    assert tolerance(2.0, [0.0, 0.0]).value == 2e-12  # no tolerance given, an exact run: rounding


def test_an_explicit_tolerance_below_the_runs_accuracy_fails(reference_rig):
    """``rtol=1e-6`` on the drive torque of two engines, and ``atol=1e-15`` on the reference
    engine's mean efficiency, are below what the runs resolve: both assertions fail naming the
    tolerance asked and the one the runs support (never widened to pass)."""
    scene = make_scene(SMALL, revolutions=1.0)
    too_tight = r"the tolerance asked, .*, is below what the runs resolve, 5 x estimated error = .*"
    with pytest.raises(AssertionError, match=r"\| mean_torque_in \| .*" + too_tight):
        assert_engines_agree(scene, columns=["mean_torque_in"], rtol=1e-6, run=CachingRunner())
    with pytest.raises(AssertionError, match=r"\| mean_efficiency \| .*" + too_tight):
        assert_efficiency(reference_rig, reference_rig.mean_efficiency, atol=1e-15)


def docs_blocks(language: str) -> list[str]:
    """The blocks of docs/pytest.md in ``language``, without those marked not run (tests/test_docs.py)."""
    blocks = re.findall(rf"```{language}\n(.*?)```", DOCS.read_text(encoding="utf-8"), re.DOTALL)
    return [b for b in blocks if not b.startswith("# not run by tests/test_docs.py")]


def test_the_docs_examples_run(pytester):
    """Every python block of docs/pytest.md, each a test module of the user's suite, passes,
    with the scene file the docs show."""
    blocks = docs_blocks("python")
    assert len(blocks) >= 3
    for toml in docs_blocks("toml"):
        name, _, text = toml.partition("\n")
        pytester.makefile(".toml", **{name.removeprefix("# ").removesuffix(".toml"): text})
    for k, block in enumerate(blocks):
        pytester.makepyfile(**{f"test_docs_{k}": block})
    result = pytester.runpytest("-p", "no:cacheprovider", "-p", "no:hypothesispytest", "-W",
                                "error::cardan_exudyn.testing.CardanToleranceWarning")
    tests = sum(len(re.findall(r"^def test_", block, re.MULTILINE)) for block in blocks)
    assert result.ret == 0 and result.parseoutcomes()["passed"] >= tests
