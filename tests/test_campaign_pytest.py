"""Validation campaigns in a user's pytest suite: the ``rig_campaign`` fixture (entry point ``pytest11``
``rigdata``) and ``assert_model_valid``, run by pytest's own ``pytester`` on a tiny campaign (two
recordings of 2 revolutions, the reference engine, no Monte Carlo), as a user meets them."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

import rigdata
import rigdata.campaign.plugin  # noqa: F401 (imported here: see below)
from cardan_exudyn.engines import get_engine
from rigdata.campaign import campaign
from rigdata.synthetic import write

pytest_plugins = ["pytester"]

# pytester's in-process runs forget the modules they import, and numpy's C extensions cannot be
# imported twice in a process: the engine and the campaign's modules are imported here, and one campaign
# runs here (fixture `recordings`) so that every module a campaign imports on first use is loaded too
get_engine("reference")

DOCS = Path(__file__).resolve().parents[1] / "docs" / "pytest.md"
FRICTION_KEYS = ", ".join(f'"joint.pairs.{pair}.friction_coefficient"'
                          for pair in ("input_spider", "spider_output", "frame_input", "output_frame"))


def settings(angle: float, friction: float, seed: int) -> rigdata.RigSettings:
    """A short recording at 20 N m with exact transducers and small noise: ``u_D`` about 0.006."""
    return rigdata.RigSettings(revolutions=2.0, shaft_angle_deg=angle, friction=friction, seed=seed,
                               input_torque=20.0, noise=5e-4, offsets=(0.0, 0.0), drifts=(0.0, 0.0))


def campaign_text(validation: str) -> str:
    """One friction coefficient for every pair, calibrated on ``calibration.csv``, validated on
    ``validation``."""
    return f"""scene = "rig"
engines = ["reference"]
monte_carlo = 0

[parameters.friction]
keys = [{FRICTION_KEYS}]
initial = 0.2
bounds = [0.0, 0.6]

[[recording]]
file = "calibration.csv"
shaft_angle_deg = 20
use = "calibration"

[[recording]]
file = "{validation}"
shaft_angle_deg = 30
use = "validation"
"""


@pytest.fixture(scope="module")
def recordings(tmp_path_factory) -> Path:
    """A calibration and a validation recording written with friction 0.1, a second validation
    recording with friction 0.4 (the model calibrated on the first cannot match it), and a campaign
    file for each validation recording: ``consistent.toml``, ``inconsistent.toml``."""
    where = tmp_path_factory.mktemp("campaign")
    write(where / "calibration.csv", "csv", settings(20.0, 0.1, 1))
    write(where / "validation.csv", "csv", settings(30.0, 0.1, 2))
    write(where / "other_friction.csv", "csv", settings(30.0, 0.4, 3))
    (where / "consistent.toml").write_text(campaign_text("validation.csv"), encoding="utf-8")
    (where / "inconsistent.toml").write_text(campaign_text("other_friction.csv"), encoding="utf-8")
    campaign(where / "consistent.toml", workers=1)  # loads what a campaign imports (see above)
    return where


USER_TEST = """
from rigdata.campaign.testing import assert_model_valid


def test_model_is_valid(rig_campaign):
    result = rig_campaign(r"{path}", workers=1)
    print("model_runs =", result.timing["model_runs"])
    assert_model_valid(result)
"""


def run_user_test(pytester: pytest.Pytester, campaign_file: Path, *args: str) -> pytest.RunResult:
    """A user's test module calling ``rig_campaign`` and ``assert_model_valid``, run in this process."""
    pytester.makepyfile(test_user=USER_TEST.format(path=campaign_file))
    return pytester.runpytest("-p", "no:hypothesispytest", "-s", *args)


def model_runs(result: pytest.RunResult) -> int:
    """The model runs the session's campaign made (printed by the user's test)."""
    found = re.findall(r"model_runs = (\d+)", result.stdout.str())
    assert len(found) == 1, result.stdout.str()
    return int(found[0])


def test_consistent_campaign_passes(pytester, recordings):
    """Validation recording written with the calibration recording's friction: the model is valid."""
    result = run_user_test(pytester, recordings / "consistent.toml")
    result.assert_outcomes(passed=1)
    assert model_runs(result) > 0


def test_resolvable_model_error_fails_with_the_table(pytester, recordings):
    """Validation recording written with 4 times the friction: assert_model_valid fails with the table
    of that recording, its comparison error positive (the calibrated model loses less than the rig)."""
    result = run_user_test(pytester, recordings / "inconsistent.toml")
    result.assert_outcomes(failed=1)
    result.stdout.fnmatch_lines([
        "*AssertionError: the model error is resolvable in 1 of 1 validation recordings (k = 1.96):",
        "*| recording | use | comparison error | expanded u_val | model error interval | dominant |",
        "*|---|---|---|---|---|---|",
        "*| other_friction.csv | validation | E = +0.0* | k u_val = * | [[]+0.0*, +0.0*] | u_* |",
    ])
    assert "| calibration.csv |" not in result.stdout.str()


def test_second_session_reuses_the_journal(pytester, recordings):
    """A second session reruns no model (journal in pytest's cache); --rig-campaign-no-cache and
    -p no:cacheprovider run them all again."""
    path = recordings / "consistent.toml"
    first = run_user_test(pytester, path)
    second = run_user_test(pytester, path)
    second.assert_outcomes(passed=1)
    assert model_runs(first) > 0
    assert model_runs(second) == 0
    assert model_runs(run_user_test(pytester, path, "--rig-campaign-no-cache")) == model_runs(first)
    assert model_runs(run_user_test(pytester, path, "-p", "no:cacheprovider")) == model_runs(first)


def test_the_docs_example_runs(pytester, recordings):
    """The rig_campaign example of docs/pytest.md passes on the consistent campaign, put where it looks."""
    blocks = re.findall(r"```python\n(# not run by tests/test_docs\.py: .*?campaign.*?)```",
                        DOCS.read_text(encoding="utf-8"), re.DOTALL)
    assert len(blocks) == 1
    target = pytester.path / "tests" / "data"
    target.mkdir(parents=True)
    for name in ("calibration.csv", "validation.csv"):
        (target / name).write_bytes((recordings / name).read_bytes())
    (target / "campaign.toml").write_text(campaign_text("validation.csv"), encoding="utf-8")
    pytester.makepyfile(test_docs_campaign=blocks[0])
    pytester.runpytest("-p", "no:hypothesispytest").assert_outcomes(passed=2)
