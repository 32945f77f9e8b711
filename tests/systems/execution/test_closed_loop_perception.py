"""The receding-horizon controller re-perceiving: its observed scene from ``ScenePerception`` on the
world's camera (small images) at every re-plan, and a failed frame keeping the last good scene."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from closed_loop_support import controller_of, run_controller
from pydrake.systems.analysis import Simulator
from sto_support import spec

from hlp_drake.commands.run_scene import DEFAULT_SCENE
from hlp_drake.scene.io import load_scene
from hlp_drake.systems.low_level.control_sequence import ControlSequence
from hlp_drake.systems.low_level.outcome import Prediction, RolloutOutcome
from hlp_drake.systems.low_level.result import LowLevelResult
from hlp_drake.systems.low_level.sto.pool import RolloutPool
from hlp_drake.systems.low_level.sto.rollout_world import RolloutWorld
from hlp_drake.systems.perception.cameras import CameraConfig, PerceptionConfig
from hlp_drake.systems.perception.perception import Perception, unperceived_scene
from hlp_drake.systems.scenario import Scenario
from hlp_drake.systems.world.world import make_world_diagram, world_plant

SETTINGS = (
    "planner: {low_level: {samples: 2, workers: 1, verify: false}}\n"
    "closed_loop: {replan_period: 0.4, iterations: 1, rollouts: 2}\n"
)
CAMERA = CameraConfig(width=320, height=240, depth_noise=0.001, dropout=0.01, seed=4)


@pytest.fixture(scope="module")
def scenario() -> Scenario:
    perception = PerceptionConfig(source="camera", cameras=(CAMERA,))
    return Scenario(scene=load_scene(DEFAULT_SCENE), perception=perception).updated(SETTINGS)


def hold(scenario: Scenario, duration: float) -> ControlSequence:
    start = RolloutWorld(spec(scenario)).start_positions
    return ControlSequence(np.array([0.0, duration]), np.vstack([start, start]))


def far_outcome(scenario: Scenario) -> RolloutOutcome:
    """A rollout that expected every object 10 m away: any observed scene has moved far from it."""
    positions = np.full((2, len(scenario.scene.objects), 3), 10.0)
    prediction = Prediction(np.array([0.0, 2.0]), positions, np.zeros((2, 3)))
    return RolloutOutcome(1.0, {}, True, None, 0.0, prediction=prediction)


def test_the_controller_re_perceives_the_camera_scene_at_every_re_plan(scenario):
    calls = []

    def initialiser(scene, robot) -> ControlSequence | None:
        calls.append(scene)  # no new plan (None): the remainder is re-optimised

    record, _, _ = run_controller(
        scenario, hold(scenario, 1.6), 0.9, outcome=far_outcome(scenario), initialiser=initialiser
    )  # re-plans at 0.4 s and 0.8 s
    assert record.replans == 2 and record.observations == 3 and record.observation_failures == 0
    assert len(calls) == 1  # far from the initial plan at 0.4 s (not from the re-plan's rollout at 0.8 s)
    truth = scenario.scene
    for seen in (*calls, record.scene):
        assert seen is not truth and seen.target.name == truth.target.name
        assert {o.name for o in seen.obstacles} == {f"object_{k}" for k in range(1, len(truth.obstacles) + 1)}
        error = np.hypot(seen.target.x - truth.target.x, seen.target.y - truth.target.y)
        assert 0.0 < error < 0.015  # the perception's error, not the plant's pose
    assert calls[0] != record.scene  # the 0.8 s frame (its noise drawn at its time), perceived again


def test_a_failed_frame_at_a_re_plan_keeps_the_last_good_scene_and_its_reason(scenario):
    world = make_world_diagram(scenario, cameras=False)
    plant, _ = world_plant(world)
    good = replace(scenario.scene, name="seen")
    with RolloutPool(1) as pool:
        controller = controller_of(scenario, plant, pool)
        simulator = Simulator(controller)
        context = simulator.get_mutable_context()
        x = plant.GetPositionsAndVelocities(plant.CreateDefaultContext())
        controller.GetInputPort("state").FixValue(context, x)
        controller.GetInputPort("initial").FixValue(
            context, LowLevelResult(hold(scenario, 1.6), None, True, None)
        )
        controller.GetInputPort("scene").FixValue(context, good)
        simulator.Initialize()
        controller.GetInputPort("scene").FixValue(context, unperceived_scene(good))
        controller.GetInputPort("perception").FixValue(
            context, Perception(unperceived_scene(good), "no table plane found")
        )
        simulator.AdvanceTo(0.5)  # one re-plan, on the failed frame
        record = controller.record(context)
    assert record.replans == 1 and record.observations == 2 and record.observation_failures == 1
    assert record.observation_reason == "no table plane found"
    assert record.observed == good and record.scene == good  # planned on the last good scene
