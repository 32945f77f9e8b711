"""Closed-loop execution: the receding-horizon controller on its own, and its model error."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from closed_loop_support import run_controller
from sto_support import spec

from hlp_drake.commands.run_scene import DEFAULT_SCENE
from hlp_drake.errors import HlpError
from hlp_drake.scene.io import load_scene
from hlp_drake.systems.execution.receding_horizon import remainder
from hlp_drake.systems.low_level.control_sequence import ControlSequence
from hlp_drake.systems.low_level.outcome import Prediction, RolloutOutcome
from hlp_drake.systems.low_level.sto.rollout_world import RolloutWorld
from hlp_drake.systems.planning.diagram import ObservedScenePlanner, make_planning_diagram
from hlp_drake.systems.scenario import Scenario
from hlp_drake.systems.world.robot_description import MOBILE_UR5
from hlp_drake.systems.world.uncertainty import UncertaintyConfig, sample_perturbation
from hlp_drake.systems.world.world import make_world_diagram, world_plant

SETTINGS = (
    "planner: {low_level: {samples: 2, workers: 1, verify: false}}\n"
    "closed_loop: {replan_period: 0.4, iterations: 1, rollouts: 3}\n"
)


@pytest.fixture(scope="module")
def scenario():
    return Scenario(scene=load_scene(DEFAULT_SCENE)).updated(SETTINGS)


def forward(start: np.ndarray, distance: float, duration: float) -> ControlSequence:
    """The robot's base moving ``distance`` along x from ``start`` in ``duration`` s (4 steps)."""
    times = np.linspace(0.0, duration, 5)
    knots = np.tile(start, (5, 1))
    knots[:, 0] += np.linspace(0.0, distance, 5)
    return ControlSequence(times, knots)


def test_the_remainder_starts_where_the_sequence_is_and_keeps_its_later_knots():
    sequence = forward(np.zeros(11), 0.2, 2.0)
    rest = remainder(sequence, 0.7)
    assert rest.duration == pytest.approx(1.3) and rest.knots[0, 0] == pytest.approx(0.07)
    np.testing.assert_array_equal(rest.knots[1:], sequence.knots[2:])
    assert remainder(sequence, 2.0) is None


def test_the_controller_re_optimises_every_period_within_its_budget_and_the_robot_follows(scenario):
    start = RolloutWorld(spec(scenario)).start_positions
    sequence = forward(start, 0.05, 1.6)
    record, desired, q = run_controller(scenario, sequence, 1.0)
    assert record.replans == 2 and record.t0 == pytest.approx(0.8)  # at 0.4 s and 0.8 s
    assert 2 <= record.rollouts <= 2 * scenario.closed_loop.rollouts
    assert record.t0 + record.sequence.duration == pytest.approx(sequence.duration)  # the same end
    trajectory = record.sequence.to_trajectory()
    np.testing.assert_allclose(desired[:11], trajectory.value(1.0 - record.t0).ravel())
    assert abs(q[0] - desired[0]) < 0.01  # the base follows the command
    again, _, _ = run_controller(scenario, sequence, 1.0)  # the same seed, the same commands
    np.testing.assert_array_equal(again.sequence.knots, record.sequence.knots)


def test_the_closed_loops_rollout_budget_ends_the_re_optimisations(scenario):
    """An execution the controller cannot rescue ends: once ``max_rollouts`` are spent the
    commanded sequence plays to its end."""
    start = RolloutWorld(spec(scenario)).start_positions
    sequence = forward(start, 0.05, 1.6)
    capped = scenario.updated("closed_loop: {max_rollouts: 1}\n")
    record, desired, _ = run_controller(capped, sequence, 1.3)  # periods at 0.4, 0.8 and 1.2 s
    assert (record.replans, record.rollouts, record.budget_spent) == (1, 1, True)
    assert record.t0 == pytest.approx(0.4) and record.to_dict()["budget_spent"] is True
    np.testing.assert_allclose(desired[:11], record.sequence.to_trajectory().value(1.3 - 0.4).ravel())
    with pytest.raises(HlpError, match="closed_loop.max_rollouts"):
        scenario.updated("closed_loop: {max_rollouts: 0}\n")


def test_model_error_is_seeded_per_scene_and_changes_the_world(scenario):
    scene = scenario.scene
    config = UncertaintyConfig(enabled=True, seed=3)
    error = sample_perturbation(config, scene)
    assert error == sample_perturbation(config, scene)
    assert error != sample_perturbation(UncertaintyConfig(enabled=True, seed=4), scene)
    offsets = np.array([[e.dx, e.dy] for e in error.objects.values()])
    assert 0 < np.max(np.abs(offsets)) < 5 * config.position_sigma
    assert all(0.5 <= e.mass_scale <= 2.0 and 0.7 <= e.friction_scale <= 1.3 for e in error.objects.values())
    true = error.true_scene(scene)
    world = make_world_diagram(scenario, model_error=error)
    plant, _ = world_plant(world)
    context = plant.CreateDefaultContext()
    target = plant.GetBodyByName(scene.target.name)
    p = target.EvalPoseInWorld(context).translation()
    assert p[:2] == pytest.approx([true.target.x, true.target.y], abs=1e-9)
    assert target.default_mass() == pytest.approx(
        make_world_diagram(scenario)
        .GetSubsystemByName("plant")
        .GetBodyByName(scene.target.name)
        .default_mass()
        * error.objects[scene.target.name].mass_scale
    )


def test_the_observed_scene_planner_plans_on_the_observed_scene_from_where_the_robot_is(scenario):
    world = RolloutWorld(spec(scenario))
    world.begin(forward(world.start_positions, 0.0, 1.0))
    robot = world.states()[MOBILE_UR5.name]
    robot[0] += 0.02  # the base 2 cm on
    template = scenario.scene
    pushed = template.obstacles[0]
    scene = replace(template, obstacles=(pushed.moved(pushed.x + 0.03, pushed.y), *template.obstacles[1:]))
    planning = make_planning_diagram(scenario)
    sequence = ObservedScenePlanner(planning, lambda t: ControlSequence.from_trajectory(t, 0.5))(scene, robot)
    np.testing.assert_allclose(sequence.knots[0], robot[:11])
    assert sequence.duration > 1.0


def test_an_object_far_from_where_the_plan_expected_it_asks_for_a_new_initial_sequence(scenario):
    start = RolloutWorld(spec(scenario)).start_positions
    sequence, fresh = forward(start, 0.05, 1.6), forward(start, 0.0, 1.0)
    positions = np.array([[o.x, o.y, 0.8] for o in scenario.scene.objects])
    calls = []

    def initialiser(scene, robot):
        calls.append((scene, robot))
        return fresh

    def outcome(offset: float) -> RolloutOutcome:
        shifted = positions + [offset, 0.0, 0.0]
        prediction = Prediction(np.array([0.0, 2.0]), np.stack([shifted, shifted]), np.zeros((2, 3)))
        return RolloutOutcome(1.0, {}, True, None, 0.0, prediction=prediction)

    record, _, _ = run_controller(scenario, sequence, 0.5, outcome=outcome(0.0), initialiser=initialiser)
    assert record.replans == 1 and record.initialised == 0 and not calls  # as expected: no new plan
    far = 2 * scenario.closed_loop.replan_distance
    record, _, _ = run_controller(scenario, sequence, 0.5, outcome=outcome(far), initialiser=initialiser)
    assert record.replans == 1 and record.initialised == 1 and len(calls) == 1
    assert calls[0][0].target.name == scenario.scene.target.name and len(calls[0][1]) == 22
    assert record.observations == 2 and record.observation_failures == 0  # at the start and the re-plan


def test_a_verified_sequence_on_track_is_kept_and_re_optimised_once_off_track(scenario):
    sequence = forward(RolloutWorld(spec(scenario)).start_positions, 0.0, 1.6)  # the robot holds still
    positions = np.array([[o.x, o.y, 0.8] for o in scenario.scene.objects])

    def verified(offset: float, *, passed: bool = True) -> RolloutOutcome:
        shifted = positions + [offset, 0.0, 0.0]
        prediction = Prediction(np.array([0.0, 2.0]), np.stack([shifted, shifted]), np.zeros((2, 3)))
        check = RolloutOutcome(1.0, {}, passed, None, 0.0, prediction=prediction)
        return RolloutOutcome(1.0, {}, True, None, 0.0, prediction=prediction, verification=check)

    record, desired, _ = run_controller(scenario, sequence, 1.0, outcome=verified(0.0))
    assert (record.on_track, record.replans, record.rollouts) == (2, 0, 0)  # at 0.4 s and 0.8 s
    assert record.sequence is not None and record.t0 == 0.0 and record.to_dict()["on_track"] == 2
    np.testing.assert_allclose(desired[:11], sequence.to_trajectory().value(1.0).ravel())
    off = 2 * scenario.closed_loop.track_distance  # every object 1 cm from where it was verified
    for outcome in (verified(off), verified(0.0, passed=False)):
        record, _, _ = run_controller(scenario, sequence, 1.0, outcome=outcome)
        assert (record.on_track, record.replans) == (0, 2) and record.track is None
    always = scenario.updated("closed_loop: {track_distance: 0.0}\n")
    record, _, _ = run_controller(always, sequence, 1.0, outcome=verified(0.0))
    assert (record.on_track, record.replans) == (0, 2)


class _MovingEnd:
    """A command whose reach ends at ``ends[k]`` when asked the k-th time (a re-plan moving it)."""

    def __init__(self, *ends: float) -> None:
        self._ends = list(ends)

    def end(self, root_context) -> float:
        return self._ends.pop(0) if len(self._ends) > 1 else self._ends[0]


SETTLE_S = 0.7


@pytest.mark.parametrize(
    "ends, settled",
    [
        ((1.0,), 1.0 + SETTLE_S),  # open loop: the end stays
        ((1.0, 1.5), 1.5 + SETTLE_S),  # a re-plan made the reach longer: simulated on to its end
        ((2.0, 0.2), 2.0),  # shorter, ending before the time simulated (gen2-9-33 with model error)
    ],
)
def test_the_reach_is_simulated_to_its_end_wherever_a_re_plan_moves_it(ends, settled):
    from pydrake.systems.analysis import Simulator
    from pydrake.systems.primitives import ConstantVectorSource

    from hlp_drake.systems.execution.command import advance_through_reach

    simulator = Simulator(ConstantVectorSource([0.0]))
    assert advance_through_reach(simulator, _MovingEnd(*ends), settle_s=SETTLE_S) == pytest.approx(settled)
    assert simulator.get_context().get_time() == pytest.approx(settled)
