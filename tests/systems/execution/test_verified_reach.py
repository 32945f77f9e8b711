"""The execution starts where the low-level planner's accepted rollout in its very world ended."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from sto_support import spec
from test_closed_loop import forward  # the base moving along x

from hlp_drake.commands.run_scene import DEFAULT_SCENE
from hlp_drake.scene.io import load_scene
from hlp_drake.systems.execution.run import plan_and_execute, verified_reach
from hlp_drake.systems.low_level.control_sequence import ControlSequence
from hlp_drake.systems.low_level.outcome import RolloutStart
from hlp_drake.systems.low_level.result import LowLevelResult
from hlp_drake.systems.low_level.sto.pool import RolloutPool, SceneRollouts
from hlp_drake.systems.low_level.sto.rollout_world import RolloutWorld
from hlp_drake.systems.scenario import Scenario
from hlp_drake.systems.world.model import world_key
from hlp_drake.systems.world.world import add_position_trajectory, make_world_diagram, world_plant


@pytest.fixture(scope="module")
def scenario():  # executed in the planner's own model: the accepted rollout is the execution's reach
    return Scenario(scene=load_scene(DEFAULT_SCENE)).updated("world: model")


def test_a_rollout_on_the_execution_model_ends_exactly_where_the_execution_does(scenario):
    verifier = RolloutWorld(spec(scenario))
    sequence = forward(verifier.start_positions, 0.3, 1.3)  # into the first row: it pushes
    outcome = verifier.rollout(sequence)
    final = outcome.final
    key = world_key(scenario.scene, scenario.executed_model, scenario.success.settle_s)
    assert final.world_key == key and final.time == sequence.duration + scenario.success.settle_s
    # The execution's world (its own diagram, simulated in one go) reaches the very same state.
    builder = DiagramBuilder()
    world = builder.AddSystem(make_world_diagram(scenario))
    plant, _ = world_plant(world)
    add_position_trajectory(builder, world, sequence.to_trajectory())
    simulator = Simulator(builder.Build())
    simulator.AdvanceTo(final.time)
    context = plant.GetMyContextFromRoot(simulator.get_context())
    moved = 0.0
    for name, x in final.states.items():
        executed = plant.GetPositionsAndVelocities(context, plant.GetModelInstanceByName(name))
        np.testing.assert_array_equal(x, executed)
        if name != "mobile_ur5":
            moved = max(
                moved,
                float(
                    np.linalg.norm(
                        x[4:7] - plant.GetDefaultPositions(plant.GetModelInstanceByName(name))[4:7]
                    )
                ),
            )
    assert moved > 1e-3  # an object was pushed: the state is not just the start's
    # A rollout from another start keeps no end state, nor does one on the reduced model.
    assert verifier.rollout(sequence, RolloutStart(verifier.states())).final is None
    reduced = SceneRollouts(spec(scenario.updated("planner: {low_level: {reduced_model: true}}")))
    assert reduced.rollout(sequence).final is None and reduced.verify(sequence).final is not None


def test_only_a_verification_in_the_executed_worlds_own_world_is_reused(scenario):
    verifier = RolloutWorld(spec(scenario))
    verified = verifier.rollout(forward(verifier.start_positions, 0.05, 0.5))
    passed = replace(verified, verification=verified)
    result = LowLevelResult(ControlSequence(np.array([0.0, 1.0]), np.zeros((2, 11))), passed, True, None)
    key = world_key(scenario.scene, scenario.executed_model, scenario.success.settle_s)
    assert verified_reach(result, key) is verified.final
    searched = scenario.updated("planner: {low_level: {seed: 1}}")  # another search, the same world
    assert verified_reach(result, world_key(searched.scene, searched.world_model, 1.0)) is verified.final
    other = scenario.updated("plant: {time_step: 0.005}")  # another world: another key
    assert verified_reach(result, world_key(other.scene, other.world_model, 1.0)) is None
    assert verified_reach(replace(result, outcome=replace(passed, verification=None)), key) is None


@pytest.mark.slow  # the default scene executed twice
def test_an_execution_from_the_verified_reach_gives_the_simulated_executions_result(scenario):
    with RolloutPool(1) as pool:
        reused = plan_and_execute(scenario, pool=pool)
        simulated = plan_and_execute(scenario.updated("planner: {low_level: {verify: false}}"), pool=pool)
    assert reused.reach_reused and not simulated.reach_reused
    assert reused.success and simulated.success
    for attribute in ("objects_moved", "objects_dropped", "target_distance", "simulated_s", "grasp_held"):
        assert getattr(reused, attribute) == getattr(simulated, attribute), attribute
    assert reused.rollouts == simulated.rollouts


def test_a_grasp_whose_simulation_diverges_leaves_the_reach_verdict_standing(scenario, monkeypatch):
    from hlp_drake.commands.run_scene import exit_status, verdict
    from hlp_drake.systems.execution import reach

    def diverging(*args, **kwargs):
        raise SystemExit("Failure at x.h:2897 in SetPositions(): condition 'AllFinite(q)' failed.")

    monkeypatch.setattr(reach, "grasp_and_lift", diverging)
    with RolloutPool(1) as pool:
        result = plan_and_execute(scenario, pool=pool)
    assert result.success and result.failure_reason is None and exit_status(result) == 0
    assert result.grasp_held is False
    assert result.grasp_failure == "simulation failed: the simulation diverged (the state turned non-finite)"
    assert result.to_dict()["grasp_failure"] == result.grasp_failure
    assert "reach success" in verdict(result) and "did not hold (simulation failed" in verdict(result)
