"""The reduced rollout model: objects sleep while nothing comes near them and go back to sleep at
rest, and the checks that decide it (``rollout_sampler``, ``sleep_schedule``, ``proximity``)."""

from __future__ import annotations

import numpy as np
import pytest
from sto_support import on, short, spec

from hlp_drake.systems.low_level.control_sequence import ControlSequence
from hlp_drake.systems.low_level.outcome import RolloutStart
from hlp_drake.systems.low_level.sto.pool import SceneRollouts
from hlp_drake.systems.low_level.sto.rollout_world import RolloutWorld
from hlp_drake.systems.low_level.sto.sampler import OBJECT, ROBOT, TABLE, contact_summary
from hlp_drake.systems.low_level.sto.sleep import ProximityContext, Sweep

REDUCED = "planner: {low_level: {reduced_model: true}}"
"""The reduced model, an approximation of the execution model (off by default)."""


# --- The reduced rollout model ---------------------------------------------------------------------

PUSHING_HORIZON = 3.0
"""The straight line's first 3 s on the default scene push two obstacles (Long, then Med-1 with it)."""


NUDGE = 3.0e-5
"""0.03 mm: about how far apart a pushed object's poses on the reduced and on the full model are
before the push (a sleeping object does not sag into the table under its weight as an awake one does)."""


def _own_spread(world: RolloutWorld, sequence: ControlSequence, name: str) -> tuple[np.ndarray, float]:
    """How far the full model's own rollout of ``sequence`` moves when the object ``name`` starts
    ``NUDGE`` to either side (a chain of pushes amplifies it): per object the largest gap of its
    position (m), and the largest gap of the cost."""
    base = world.rollout(sequence)
    world.begin(sequence)
    gaps, costs = [], []
    for shift in (NUDGE, -NUDGE):
        states = world.states()
        states[name][4] += shift  # x (after the quaternion)
        nudged = world.rollout(sequence, RolloutStart(states))
        gaps.append(
            np.linalg.norm(nudged.prediction.positions - base.prediction.positions, axis=2).max(axis=0)
        )
        costs.append(abs(nudged.cost - base.cost))
    return np.max(gaps, axis=0), max(costs)


SAG = 0.5e-3
"""An awake object sinks this far into the table at most, a sleeping one not at all (0.35 mm at 20 ms)."""
CHAINED = "FailOnTouchObstacleMed-1"
"""Pushed by Long before the robot itself comes near it."""


def _gaps_within_own_spread(
    world: RolloutWorld, sequence: ControlSequence, positions: np.ndarray
) -> np.ndarray:
    """Per object, how far ``positions`` (a rollout's samples of ``sequence``) get from the full
    model's; asserts it is within the full model's own spread (``_own_spread`` of ``CHAINED``) and the sag."""
    gap = np.linalg.norm(positions - world.simulate(sequence).positions, axis=2).max(axis=0)
    spread, _ = _own_spread(world, sequence, CHAINED)
    assert np.all(gap <= spread + SAG), (gap, spread)
    return gap


def test_the_reduced_model_lets_only_objects_nothing_comes_near_sleep(scene, trajectories, world):
    config = on(scene, REDUCED)
    reduced = SceneRollouts(spec(config))
    sequence = short(ControlSequence.from_trajectory(trajectories["line"], 0.5), PUSHING_HORIZON)
    full, samples = world.simulate(sequence), reduced.simulate(sequence)
    names = [obj.name for obj in scene.objects]
    pushed = {
        n for n, d in zip(names, np.linalg.norm(full.positions[-1] - full.positions[0], axis=1)) if d > 0.01
    }
    assert len(pushed) == 2 and samples.asleep and samples.switches > 0
    approach = Sweep(world).approach_times(sequence, config.low_level.weld_clearance)
    initially = reduced.sleep_schedule(sequence).initially_asleep()
    assert initially and all(approach[name] > config.low_level.weld_lookahead for name in initially)
    assert "FailOnTouchObstacleLong" not in initially  # the one the robot pushes at once starts awake
    # Sleeping objects simply stay put (they do not sag); the pushed ones land as far from the full
    # model's as a 0.03 mm nudge of the chained one moves the full model itself.
    gap = _gaps_within_own_spread(world, sequence, samples.positions)
    untouched = [n not in pushed and n != "Target" for n in names]
    assert np.all(gap[untouched] < SAG)
    _, cost_spread = _own_spread(world, sequence, CHAINED)
    a, b = reduced.rollout(sequence), world.rollout(sequence)
    assert a.success == b.success and a.fallen == b.fallen
    assert abs(a.cost - b.cost) <= cost_spread + 1e-3 * b.cost
    assert a.asleep == samples.asleep and b.asleep == () and b.switches == 0
    off = config.updated("planner: {low_level: {reduced_model: false}}")
    assert SceneRollouts(spec(off)).rollout(sequence).terms == b.terms  # off: the full model


def test_an_object_pushed_towards_a_sleeping_one_wakes_it_from_the_sample_before(scene, trajectories, world):
    sequence = short(ControlSequence.from_trajectory(trajectories["line"], 0.5), PUSHING_HORIZON)
    chained = CHAINED
    config = on(
        scene, "planner: {low_level: {reduced_model: true, weld_clearance: 0.01, weld_lookahead: 0.0}}"
    )  # the schedule wakes late...
    reduced = SceneRollouts(spec(config))
    assert chained in reduced.sleep_schedule(sequence).initially_asleep()
    samples = reduced.simulate(sequence)  # ...so the check during the rollout must
    assert chained not in samples.asleep and samples.switches >= 2
    _gaps_within_own_spread(world, sequence, samples.positions)


def test_an_object_come_to_rest_after_a_push_goes_back_to_sleep(scene, trajectories, world):
    pushing = short(ControlSequence.from_trajectory(trajectories["line"], 0.5), 2.0)  # pushes Long aside
    times = np.append(pushing.times, pushing.times[-1] + np.array([1.0, 2.0]))
    sequence = ControlSequence(
        times, np.vstack([pushing.knots, pushing.knots[-2], pushing.knots[0]])
    )  # ...back
    samples = SceneRollouts(spec(on(scene, REDUCED))).simulate(sequence)
    pushed = scene.objects.index(next(o for o in scene.objects if o.name == "FailOnTouchObstacleLong"))
    assert np.linalg.norm(samples.positions[-1, pushed] - samples.positions[0, pushed]) > 0.05
    assert set(samples.asleep) == {obj.name for obj in scene.objects}  # it too, once the robot is away
    _gaps_within_own_spread(world, sequence, samples.positions)


def test_a_rollout_restarted_from_its_states_goes_on_exactly(scene, trajectories, world):
    sequence = short(ControlSequence.from_trajectory(trajectories["line"], 0.5), 2.0)
    world.begin(sequence)
    world.advance_to(2.0)
    end = world.states()
    world.begin(sequence)
    world.advance_to(1.0)
    other = RolloutWorld(spec(on(scene, REDUCED)))
    other.begin(sequence, time=1.0, states=world.states())
    other.advance_to(2.0)
    assert other.states().keys() == end.keys()
    for name, x in other.states().items():
        np.testing.assert_array_equal(x, end[name])


def test_a_rollout_from_a_given_state_starts_there(scene, trajectories, world):
    sequence = short(ControlSequence.from_trajectory(trajectories["line"], 0.5), 1.0)
    world.begin(sequence)
    states = world.states()
    obstacle = scene.obstacles[0].name
    states[obstacle] = states[obstacle].copy()
    states[obstacle][4:6] += [0.0, 0.02]  # the obstacle 2 cm to the left (x, y, z follow the quaternion)
    samples = SceneRollouts(spec(on(scene, REDUCED))).simulate(sequence, RolloutStart(states))
    assert samples.positions[0, 1, 1] == pytest.approx(scene.obstacles[0].y + 0.02, abs=1e-6)
    assert samples.positions[-1, 1, 1] == pytest.approx(scene.obstacles[0].y + 0.02, abs=1e-3)


# --- The checks' queries and readings --------------------------------------------------------------


def _closest_by_body_pair(pairs) -> dict[tuple[int, int], float]:
    closest: dict[tuple[int, int], float] = {}
    for a, b, distance in pairs:
        key = (min(a, b), max(a, b))
        closest[key] = min(distance, closest.get(key, np.inf))
    return closest


def test_the_checks_see_the_robot_and_object_pairs_at_their_full_distances(scene, trajectories, world):
    sequence = short(ControlSequence.from_trajectory(trajectories["line"], 0.5), PUSHING_HORIZON)
    world.begin(sequence)
    world.advance_to(1.5)  # pushing Long, near the others
    context = world.diagram.CreateDefaultContext()  # every geometry pair checked there
    for name, x in world.states().items():
        world.plant.SetPositionsAndVelocities(
            world.plant.GetMyMutableContextFromRoot(context), world.plant.GetModelInstanceByName(name), x
        )
    query = world.world.GetOutputPort("query_object").Eval(world.world.GetMyContextFromRoot(context))
    raw = [
        (world.geometry_body[p.id_A], world.geometry_body[p.id_B], p.distance)
        for p in query.ComputeSignedDistancePairwiseClosestPoints(0.15)
    ]
    everything = _closest_by_body_pair(raw)
    watched = world.robot_bodies | world.object_bodies
    expected = {
        (a, b): d
        for (a, b), d in everything.items()
        if {a, b} <= watched and not {a, b} <= world.robot_bodies
    }
    pairs = world.close_pairs(0.15)
    assert len(expected) >= 3 and any(a in world.robot_bodies or b in world.robot_bodies for a, b in expected)
    assert _closest_by_body_pair(pairs) == pytest.approx(expected, abs=1e-6)  # GJK's tolerance
    assert len(pairs) < len(raw) / 3  # no table, support sphere or robot-robot pairs left


def test_the_commanded_sweep_checks_the_robot_against_the_objects_only(world):
    proximity = ProximityContext(world, objects_apart=True)
    pairs = proximity.close_pairs(1.0)  # the objects stand within 1 m of each other and of the table
    assert pairs and all((a in world.robot_bodies) != (b in world.robot_bodies) for a, b, _ in pairs)
    assert all(a in world.robot_bodies | world.object_bodies for pair in pairs for a in pair[:2])


def test_object_positions_and_speeds_are_their_bodies_poses_and_velocities(scene, trajectories, world):
    sequence = short(ControlSequence.from_trajectory(trajectories["line"], 0.5), PUSHING_HORIZON)
    world.begin(sequence)
    world.advance_to(1.5)
    plant, context = world.plant, world.plant.CreateDefaultContext()
    for name, x in world.states().items():
        plant.SetPositionsAndVelocities(context, plant.GetModelInstanceByName(name), x)
    velocities = [body.EvalSpatialVelocityInWorld(context) for body in world.objects]
    speed, turn = world.object_speeds()
    assert np.max(speed) > 0.01  # Long is being pushed
    np.testing.assert_allclose(speed, [np.linalg.norm(v.translational()) for v in velocities], atol=1e-12)
    np.testing.assert_allclose(turn, [np.linalg.norm(v.rotational()) for v in velocities], atol=1e-12)
    np.testing.assert_allclose(
        world.object_positions(), [body.EvalPoseInWorld(context).translation() for body in world.objects]
    )


class _Contact:
    def __init__(self, a: int, b: int, force: list[float]) -> None:
        self._a, self._b, self._force = a, b, np.array(force)

    def bodyA_index(self) -> int:
        return self._a

    def bodyB_index(self) -> int:
        return self._b

    def contact_force(self) -> np.ndarray:
        return self._force


class _Results:
    def __init__(self, *contacts: _Contact) -> None:
        self._contacts = contacts

    def num_point_pair_contacts(self) -> int:
        return len(self._contacts)

    def point_pair_contact_info(self, i: int) -> _Contact:
        return self._contacts[i]


def test_the_contact_summary_takes_the_largest_force_on_an_object_and_the_robots_table_contact():
    kind = np.array([3, ROBOT, ROBOT, OBJECT, OBJECT, TABLE])  # body 0 is the world
    assert contact_summary(_Results(), kind) == (0.0, False)
    resting = _Results(_Contact(3, 5, [0.0, 0.0, 2.0]), _Contact(5, 4, [0.0, 3.0, 4.0]))
    assert contact_summary(resting, kind) == (5.0, False)
    pushed = _Results(
        _Contact(1, 5, [0.0, 0.0, 900.0]),  # the robot on the table: not a force on an object
        _Contact(2, 3, [70.0, 0.0, 0.0]),
        _Contact(1, 2, [0.0, 80.0, 0.0]),  # robot on robot
    )
    assert contact_summary(pushed, kind) == (70.0, True)
    assert contact_summary(_Results(_Contact(5, 2, [0.0, 0.0, 1.0])), kind) == (0.0, True)
