"""The reduced rollout model: objects sleep while nothing comes near them and go back to sleep at
rest, and the checks that decide it (``rollout_sampler``, ``sleep_schedule``, ``proximity``)."""

from __future__ import annotations

import numpy as np
import pytest
from sto_support import on, short

from hlp_drake.systems.control_sequence import ControlSequence
from hlp_drake.systems.rollout_world import RolloutStart, RolloutWorld
from hlp_drake.systems.scene_rollouts import SceneRollouts
from hlp_drake.systems.sleep_schedule import Sweep

# --- The reduced rollout model ---------------------------------------------------------------------

PUSHING_HORIZON = 3.0
"""The straight line's first 3 s on the default scene push two obstacles (Long, then Med-1 with it)."""


def test_the_reduced_model_lets_only_objects_nothing_comes_near_sleep(scene, trajectories, world):
    config = on(scene)
    reduced = SceneRollouts(config)
    sequence = short(ControlSequence.from_trajectory(trajectories["sto"], 0.5), PUSHING_HORIZON)
    full, samples = world.simulate(sequence), reduced.simulate(sequence)
    names = [obj.name for obj in scene.objects]
    pushed = {
        n for n, d in zip(names, np.linalg.norm(full.positions[-1] - full.positions[0], axis=1)) if d > 0.01
    }
    assert len(pushed) == 2 and samples.asleep and samples.switches > 0
    approach = Sweep(world).approach_times(sequence, config.optimiser.weld_clearance)
    initially = reduced.sleep_schedule(sequence).initially_asleep()
    assert initially and all(approach[name] > config.optimiser.weld_lookahead for name in initially)
    assert "FailOnTouchObstacleLong" not in initially  # the one the robot pushes at once starts awake
    np.testing.assert_allclose(samples.positions, full.positions, atol=1e-3)  # sleeping ones simply stay put
    a, b = reduced.rollout(sequence), world.rollout(sequence)
    assert a.success == b.success and a.fallen == b.fallen
    assert a.cost == pytest.approx(b.cost, rel=1e-3)
    assert a.terms["disturbance"] == pytest.approx(b.terms["disturbance"], rel=1e-2)
    assert a.asleep == samples.asleep and b.asleep == () and b.switches == 0
    off = config.updated("optimiser: {reduced_model: false}")
    assert SceneRollouts(off).rollout(sequence).terms == b.terms  # off: the full model


def test_an_object_pushed_towards_a_sleeping_one_wakes_it_from_the_sample_before(scene, trajectories, world):
    sequence = short(ControlSequence.from_trajectory(trajectories["sto"], 0.5), PUSHING_HORIZON)
    chained = "FailOnTouchObstacleMed-1"  # pushed by Long before the robot itself comes near it
    config = on(scene, "optimiser: {weld_clearance: 0.01, weld_lookahead: 0.0}")  # the schedule wakes late...
    reduced = SceneRollouts(config)
    assert chained in reduced.sleep_schedule(sequence).initially_asleep()
    samples = reduced.simulate(sequence)  # ...so the check during the rollout must
    assert chained not in samples.asleep and samples.switches >= 2
    np.testing.assert_allclose(samples.positions, world.simulate(sequence).positions, atol=1e-3)


def test_an_object_come_to_rest_after_a_push_goes_back_to_sleep(scene, trajectories, world):
    pushing = short(ControlSequence.from_trajectory(trajectories["sto"], 0.5), 2.0)  # pushes Long aside
    times = np.append(pushing.times, pushing.times[-1] + np.array([1.0, 2.0]))
    sequence = ControlSequence(
        times, np.vstack([pushing.knots, pushing.knots[-2], pushing.knots[0]])
    )  # ...back
    samples = SceneRollouts(on(scene)).simulate(sequence)
    pushed = scene.objects.index(next(o for o in scene.objects if o.name == "FailOnTouchObstacleLong"))
    assert np.linalg.norm(samples.positions[-1, pushed] - samples.positions[0, pushed]) > 0.05
    assert set(samples.asleep) == {obj.name for obj in scene.objects}  # it too, once the robot is away
    np.testing.assert_allclose(samples.positions, world.simulate(sequence).positions, atol=1e-3)


def test_a_rollout_restarted_from_its_states_goes_on_exactly(scene, trajectories, world):
    sequence = short(ControlSequence.from_trajectory(trajectories["sto"], 0.5), 2.0)
    world.begin(sequence)
    world.advance_to(2.0)
    end = world.states()
    world.begin(sequence)
    world.advance_to(1.0)
    other = RolloutWorld(on(scene))
    other.begin(sequence, time=1.0, states=world.states())
    other.advance_to(2.0)
    assert other.states().keys() == end.keys()
    for name, x in other.states().items():
        np.testing.assert_array_equal(x, end[name])


def test_a_rollout_from_a_given_state_starts_there(scene, trajectories, world):
    sequence = short(ControlSequence.from_trajectory(trajectories["sto"], 0.5), 1.0)
    world.begin(sequence)
    states = world.states()
    obstacle = scene.obstacles[0].name
    states[obstacle] = states[obstacle].copy()
    states[obstacle][4:6] += [0.0, 0.02]  # the obstacle 2 cm to the left (x, y, z follow the quaternion)
    samples = SceneRollouts(on(scene)).simulate(sequence, RolloutStart(states))
    assert samples.positions[0, 1, 1] == pytest.approx(scene.obstacles[0].y + 0.02, abs=1e-6)
    assert samples.positions[-1, 1, 1] == pytest.approx(scene.obstacles[0].y + 0.02, abs=1e-3)
