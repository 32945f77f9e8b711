"""The world a run is judged in (``world``), apart from the planner's model; the success test's
reasons; the STO's acceptance margin and check on a finer model."""

from __future__ import annotations

import numpy as np
import pytest
from sto_support import on, scene, sto, trajectories  # noqa: F401 - fixtures

from hlp_drake.errors import HlpError
from hlp_drake.systems.conditions import Conditions
from hlp_drake.systems.execution.diagram import make_execution_diagram
from hlp_drake.systems.execution.run import plan_and_execute
from hlp_drake.systems.low_level.control_sequence import ControlSequence
from hlp_drake.systems.low_level.sto.optimiser import optimise
from hlp_drake.systems.low_level.sto.pool import RolloutPool
from hlp_drake.systems.scenario import Scenario, load_scenario
from hlp_drake.systems.world.judge import WorldConfig
from hlp_drake.systems.world.success import ReachEnd, SuccessConfig


def test_the_reference_world_is_finer_physics_over_the_planners_model_and_the_model_world_is_the_model():
    scenario = Scenario()
    assert scenario.world.kind == "reference"
    world, model = scenario.executed_model, scenario.world_model
    assert (model.plant.time_step, world.plant.time_step) == (0.01, 0.002)
    assert world.plant.use_sampled_output_ports and not model.plant.use_sampled_output_ports
    assert (world.contact.rim_spheres, world.contact.top_spheres, world.contact.robot_self_contact) == (
        8,
        True,
        True,
    )
    assert world.robot == model.robot and world.controller == model.controller
    mine = load_scenario(data="world: model")
    assert mine.executed_model is mine.world_model
    custom = load_scenario(data="world: {kind: reference, time_step: 0.001}")
    assert custom.executed_model.plant.time_step == 0.001 and custom.world_model.plant.time_step == 0.01
    assert Conditions(world="model").applied(scenario).world == WorldConfig(kind="model")
    with pytest.raises(
        HlpError, match=r"^overrides: world\.kind: expected one of model, reference, got 'moon'$"
    ):
        load_scenario(data="world: moon")
    with pytest.raises(HlpError, match=r"world\.time_step must be"):
        load_scenario(data="world: {time_step: 0.5}")


def test_the_execution_diagram_acts_in_the_world_and_plans_in_the_model(scene):  # noqa: F811
    handles = make_execution_diagram(on(scene))
    assert handles.plant.time_step() == 0.002
    model = make_execution_diagram(on(scene, "world: model"))
    assert model.plant.time_step() == 0.01


def _end(tcp, start, end, fallen=()):
    return ReachEnd(np.array(tcp, float), np.array(start, float), np.array(end, float), fallen, 0.80)


def test_the_success_test_names_the_real_cause(scene):  # noqa: F811
    success = SuccessConfig()
    target = scene.target
    n = len(scene.objects)
    start = np.array([[o.x, o.y, 0.8] for o in scene.objects])
    at = [target.x, target.y, 0.80]
    assert _end(at, start, start).problem(scene, success) is None
    radius = 0.5 * max(target.size[:2]) + 0.03
    far = _end([target.x + radius + 0.005, target.y, 0.80], start, start).problem(scene, success)
    assert f"the tcp ends {radius + 0.005:.3f} m from its centre (within {radius:.3f} m passes)" in far
    high = _end([target.x, target.y, 0.89], start, start).problem(scene, success)
    assert "the tcp ends 0.090 m above grasp height (within 0.030 m passes)" in high
    low = _end([target.x, target.y, 0.76], start, start).problem(scene, success)
    assert "0.040 m below grasp height" in low
    lifted = start.copy()
    lifted[n - 1, 2] += 0.05
    carried = f"lifted off the table (on the gripper or another object): {scene.objects[-1].name} by 0.050 m"
    assert _end(at, start, lifted).problem(scene, success) is None  # the paper's test passes
    assert _end(at, start, lifted).problem(scene, success, accepting=True) == carried  # a planner refuses it
    missed = _end([target.x, target.y, 0.89], start, lifted).problem(scene, success)
    assert missed.endswith(f"above grasp height (within 0.030 m passes); {carried}")  # the likely cause
    fell = _end(at, start, start, fallen=(scene.objects[1].name,)).problem(scene, success)
    assert fell == f"objects fell off the table: {scene.objects[1].name}"
    # a planner's acceptance margin shrinks the region; the test itself passes
    near = _end([target.x + radius - 0.005, target.y, 0.80], start, start)
    assert near.problem(scene, success) is None and near.problem(scene, success, shrink=0.01) is not None


def test_a_run_names_its_world_and_gives_the_models_verdict_beside_it(scene):  # noqa: F811
    cheap = "planner: {low_level: {max_rollouts: 1, samples: 1, workers: 1}}"
    results = {}
    with RolloutPool(1) as pool:
        for world in ("model", "reference"):
            results[world] = plan_and_execute(on(scene, f"{cheap}\nworld: {world}"), pool=pool)
    model, reference = results["model"], results["reference"]
    assert model.world == "model" and model.reach_reused  # the accepted rollout replayed
    assert reference.world == "reference" and not reference.reach_reused  # simulated in the world
    for result in results.values():
        assert result.model_success is True and result.false_accept == (not result.success)
        record = result.to_dict()
        assert record["world"] == result.world and record["model_success"] is True
    assert reference.simulated_s == pytest.approx(model.simulated_s, abs=0.01)


def test_a_diverging_world_is_the_scenes_failure_with_its_reason(scene, monkeypatch):  # noqa: F811
    from hlp_drake.systems.execution import reach

    def diverge(*args, **kwargs):
        raise RuntimeError("MultibodyPlant's discrete update solver failed to converge\nmore detail")

    monkeypatch.setattr(reach, "advance_through_reach", diverge)
    cheap = "planner: {low_level: {max_rollouts: 1, samples: 1, workers: 1}}"
    with RolloutPool(1) as pool:
        result = plan_and_execute(on(scene, cheap), pool=pool)
    assert not result.success and result.model_success and result.false_accept
    assert result.failure_reason == (
        "the world's simulation diverged: MultibodyPlant's discrete update solver failed to converge"
    )


def test_an_accepted_rollout_counts_only_if_it_passes_on_the_finer_check_model(scene, trajectories):  # noqa: F811
    reaching = ControlSequence.from_trajectory(trajectories["hlp"], 0.5)  # passes at 10 ms
    with RolloutPool(1) as pool:
        checked = optimise(sto(scene, "max_rollouts: 1, samples: 1"), reaching, pool)  # at 5 ms
        unchecked = optimise(sto(scene, "max_rollouts: 1, samples: 1, check_step: 0"), reaching, pool)
        margin = optimise(sto(scene, "max_rollouts: 1, samples: 1, acceptance_margin: 0.1"), reaching, pool)
    assert checked.success and (checked.verifications, checked.rejected) == (1, 0)
    assert unchecked.success and (unchecked.verifications, unchecked.verify_s) == (0, 0.0)  # its own check
    assert checked.verify_s > 0 and checked.outcome.verification is not None
    # a margin as wide as the region accepts nothing, and says why
    assert not margin.success and "not as the planner accepts it (margin 0.1 m)" in margin.failure_reason
