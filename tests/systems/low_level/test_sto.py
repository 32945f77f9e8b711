"""The STO's parts: control sequences, the noise, the rollout cost, rollout worlds and their pool."""

from __future__ import annotations

import re

import numpy as np
import pytest
from human_plans import GEN1_32, GEN2_9_30, GEN2_9_30_NEXT, chain_first_rollout, human_plan, laid_out_plan
from sto_support import on, short, spec, sto

from hlp_drake.errors import HlpError
from hlp_drake.scene.generators import generate_scene
from hlp_drake.systems.low_level.control_sequence import ControlSequence
from hlp_drake.systems.low_level.sto.cost import BLOWN_UP_COST, RolloutSamples, rollout_cost
from hlp_drake.systems.low_level.sto.optimiser import mppi_weights, sample_base_noise
from hlp_drake.systems.low_level.sto.pool import RolloutPool, SceneRollouts
from hlp_drake.systems.low_level.sto.rollout_world import RolloutWorld
from hlp_drake.systems.planning.diagram import make_planning_diagram
from hlp_drake.systems.scenario import Scenario
from hlp_drake.systems.world.start_pose import tcp_keypoint_height

# --- Control sequences -----------------------------------------------------------------------------


def test_sequence_keeps_every_keyframe_and_bounds_the_step(trajectories):
    trajectory = trajectories["hlp"]
    sequence = ControlSequence.from_trajectory(trajectory, 0.5)
    assert sequence.times[0] == 0.0 and np.all(sequence.steps <= 0.5 + 1e-9)
    assert sequence.duration == pytest.approx(trajectory.end_time() - trajectory.start_time())
    for t in trajectory.get_segment_times():  # the keyframes are knots, not cut corners
        i = int(np.argmin(np.abs(sequence.times - t)))
        assert sequence.times[i] == pytest.approx(t)
        np.testing.assert_allclose(sequence.knots[i], trajectory.value(t).ravel(), atol=1e-12)
    replay = sequence.to_trajectory()
    for t in np.linspace(0, sequence.duration, 37):
        np.testing.assert_allclose(replay.value(t), trajectory.value(t), atol=1e-9)


def test_base_velocity_is_integrated_and_the_start_stays():
    from hlp_drake.systems.low_level.control_sequence import BASE_COLUMNS
    from hlp_drake.systems.world.robot_description import MOBILE_UR5
    from hlp_drake.systems.world.start_pose import robot_position_names

    assert tuple(robot_position_names()[i] for i in BASE_COLUMNS) == MOBILE_UR5.base_joints
    sequence = ControlSequence(np.array([0.0, 0.5, 1.5]), np.zeros((3, 11)))
    velocity = np.array([[0.2, -0.1, 0.05], [0.1, 0.0, 0.0]])
    moved = sequence.with_base_velocity(velocity)
    np.testing.assert_allclose(moved.knots[0], 0.0)
    np.testing.assert_allclose(moved.knots[1, :3], [0.1, -0.05, 0.025])
    np.testing.assert_allclose(moved.knots[2, :3], [0.2, -0.05, 0.025])
    np.testing.assert_allclose(moved.knots[:, 3:], 0.0)  # the arm and fingers keep their motion
    assert moved.effort() == pytest.approx(0.5 * (0.2**2 + 0.1**2 + 0.05**2) + 1.0 * 0.1**2)
    with pytest.raises(ValueError, match="base velocities"):
        sequence.with_base_velocity(np.zeros((3, 3)))
    with pytest.raises(ValueError, match="increase"):
        ControlSequence(np.array([0.0, 0.0]), np.zeros((2, 11)))
    with pytest.raises(ValueError, match="finite"):
        ControlSequence(np.array([0.0, 1.0]), np.full((2, 11), np.nan))


def test_noise_is_seeded_and_keeps_only_part_of_its_drift():
    config = Scenario().low_level
    sequence = ControlSequence(np.linspace(0.0, 4.0, 9), np.zeros((9, 11)))
    a = sample_base_noise(np.random.default_rng(3), sequence, config.noise, 6)
    b = sample_base_noise(np.random.default_rng(3), sequence, config.noise, 6)
    np.testing.assert_array_equal(a, b)
    raw = np.random.default_rng(3).normal(size=(6, 8, 3)) * [
        config.noise.vx,
        config.noise.vy,
        config.noise.yaw_rate,
    ]
    end = np.einsum("knj,n->kj", a, sequence.steps)
    np.testing.assert_allclose(end, config.noise.end_fraction * np.einsum("knj,n->kj", raw, sequence.steps))


def test_mppi_weights_favour_the_cheapest_rollout():
    weights = mppi_weights(np.array([10.0, 20.0, 110.0]), 10.0)
    assert weights.sum() == pytest.approx(1.0)
    assert weights[0] > weights[1] > weights[2]
    assert weights[2] / weights[0] == pytest.approx(np.exp(-10.0))
    np.testing.assert_allclose(mppi_weights(np.array([5.0, 5.0]), 10.0), [0.5, 0.5])


# --- Cost ------------------------------------------------------------------------------------------


def synthetic_samples(scene, *, tcp_end, moved=None, force=0.0, blew_up=None):
    positions = np.array([[o.x, o.y, scene.table.height + o.size[2] / 2] for o in scene.objects])
    end = positions.copy()
    if moved is not None:
        end[moved[0]] += moved[1]
    height = tcp_keypoint_height(scene, Scenario().ik)
    return RolloutSamples(
        np.array([0.0, 0.5]),
        np.stack([positions, end]),
        np.array([[0.0, 0.0, height], [*tcp_end, height]]),
        np.array([0.0, force]),
        np.array([False, False]),
        blew_up,
    )


def test_cost_rewards_reaching_and_charges_falls_forces_and_blow_ups(scene):
    config = Scenario()
    height = tcp_keypoint_height(scene, config.ik)
    kwargs = {"tcp_height": height, "effort": 0.0, "step_duration": 0.5}
    target = (scene.target.x, scene.target.y)
    sto = config.low_level
    kwargs["success"] = config.success
    reached = rollout_cost(synthetic_samples(scene, tcp_end=target), scene, sto, **kwargs)
    assert reached.success and reached.failure_reason is None and reached.cost < 1.0
    short_of = rollout_cost(
        synthetic_samples(scene, tcp_end=(target[0] - 0.2, target[1])), scene, sto, **kwargs
    )
    assert not short_of.success and "pre-grasp" in short_of.failure_reason
    assert short_of.terms["goal"] == pytest.approx(sto.cost.goal_weight * 0.2)
    fell = rollout_cost(
        synthetic_samples(scene, tcp_end=target, moved=(1, [0.0, 5.0, -1.0])), scene, sto, **kwargs
    )
    assert not fell.success and scene.obstacles[0].name in fell.failure_reason
    assert fell.terms["off_table"] > 0 and fell.terms["disturbance"] > 0
    pushed = rollout_cost(synthetic_samples(scene, tcp_end=target, force=100.0), scene, sto, **kwargs)
    assert pushed.terms["force"] == pytest.approx(sto.cost.force_weight * 40.0)
    broken = rollout_cost(synthetic_samples(scene, tcp_end=target, blew_up="x sank"), scene, sto, **kwargs)
    assert broken.cost == BLOWN_UP_COST and not broken.success and "blew up" in broken.failure_reason


# --- Rollouts --------------------------------------------------------------------------------------


def test_rollouts_are_repeatable_and_the_hlp_initialisation_reaches_the_default_target(world, trajectories):
    sequence = ControlSequence.from_trajectory(trajectories["hlp"], 0.5)
    first, second = world.rollout(sequence), world.rollout(sequence)
    assert first.success, first.failure_reason
    assert first.cost == second.cost and first.terms == second.terms  # contexts are reset, not rebuilt
    assert first.simulated_s == pytest.approx(sequence.duration + world.spec.success.settle_s)


def test_rollouts_read_their_state_every_sample_period(scene, trajectories):
    config = on(scene, "planner: {low_level: {sample_period: 0.25}}\nsuccess: {settle_s: 0.0}")
    rollouts = SceneRollouts(spec(config))
    sequence = short(ControlSequence.from_trajectory(trajectories["line"], 0.5), 1.0)
    rolled, verified = rollouts.rollout(sequence), rollouts.verify(sequence)
    np.testing.assert_allclose(rolled.prediction.times, [0.0, 0.25, 0.5, 0.75, 1.0])
    np.testing.assert_array_equal(verified.prediction.times, rolled.prediction.times)
    assert verified.cost == rolled.cost  # one model: the verification is the rollout again
    with pytest.raises(HlpError, match=r"planner\.low_level\.sample_period must be > 0"):
        on(scene, "planner: {low_level: {sample_period: 0.0}}")


def test_a_gripper_closed_among_the_obstacles_does_not_carry_one_into_the_target():
    """Gen I seed 32: with the fingers open among the obstacles (and the pushes spaced for them) the
    way to the target sweeps the target off the table; closed there, the same plan passes at its
    first rollout."""
    scene = generate_scene("gen1", 32)
    person = human_plan(scene, GEN1_32)
    closed = chain_first_rollout(on(scene), person)
    assert closed.success, closed.failure_reason
    opened = chain_first_rollout(on(scene, "motion: {closed_among_obstacles: false}"), person)
    assert not opened.success and opened.fallen == ("Target",), opened.failure_reason


def test_where_the_hlps_plan_fails_at_its_first_rollout_its_next_candidates_are_tried():
    """Gen II seed 30, 9 objects: the way of the plan's row-4 push knocks the target off the table
    at its first rollout; of the next two distinct candidate plans, the first passes at its first
    rollout. The straight line has no candidates to try."""
    scene = generate_scene("gen2", 30, 9)
    config = on(scene, "planner: {low_level: {max_iterations: 1, samples: 2}}")
    person = laid_out_plan(scene, GEN2_9_30, GEN2_9_30_NEXT)
    with RolloutPool(1) as pool:
        diagram = make_planning_diagram(config, pool=pool, plan=person)
        context = diagram.CreateDefaultContext()
        diagram.GetInputPort("scene").FixValue(context, scene)
        transfer = diagram.GetSubsystemByName("robot_plan_transfer")
        count = len(transfer.GetOutputPort("robot_alternatives").Eval(transfer.GetMyContextFromRoot(context)))
        hlp = diagram.GetOutputPort("optimisation").Eval(context)
        sto = make_planning_diagram(config.updated("planner: {initial: line}"), pool=pool)
        sto_context = sto.CreateDefaultContext()
        sto.GetInputPort("scene").FixValue(sto_context, scene)
        straight = sto.GetOutputPort("optimisation").Eval(sto_context)
    assert count == 2
    assert hlp.success and hlp.start == 1 and hlp.iterations == 0 and hlp.rollouts == 1 + 2
    assert "fell off the table: Target" in chain_first_rollout(config, person).failure_reason
    assert straight.start == 0


def test_holding_still_fails_with_the_goal_cost(world, scene):
    start = world.start_positions
    outcome = world.rollout(ControlSequence(np.array([0.0, 1.0]), np.vstack([start, start])))
    assert not outcome.success and "pre-grasp" in outcome.failure_reason
    assert outcome.terms["goal"] > 100 * outcome.terms["effort"] and outcome.fallen == ()


def test_impossible_object_speed_counts_as_a_blow_up(scene, trajectories):
    config = on(scene, "planner: {low_level: {max_object_speed: 1.0e-4}}")  # any push now exceeds it
    outcome = RolloutWorld(spec(config)).rollout(ControlSequence.from_trajectory(trajectories["line"], 0.5))
    assert (
        not outcome.success and outcome.cost == BLOWN_UP_COST and "over the table" in outcome.failure_reason
    )


def test_a_drake_internal_check_failing_mid_rollout_is_a_failure_and_the_world_goes_on(scene, trajectories):
    # Non-finite state (as after a blow-up) makes Drake's SetPositions check fail inside AdvanceTo;
    # pydrake raises that as SystemExit. The rollout reports it; the world is reusable after it.
    world = RolloutWorld(spec(on(scene)))
    sequence = short(ControlSequence.from_trajectory(trajectories["line"], 0.5), 0.5)
    world.begin(sequence)
    state = world._context.get_mutable_discrete_state_vector()
    x = state.get_value().copy()
    x[-1] = np.nan
    state.SetFromVector(x)
    problem = world.advance_to(0.1)
    assert re.fullmatch(
        r"the solver failed at t = 0\.0\d s: the simulation diverged \(the state turned non-finite\)", problem
    )
    clean = RolloutWorld(spec(on(scene))).rollout(sequence)
    again = world.rollout(sequence)
    assert (again.cost, again.success, again.fallen) == (clean.cost, clean.success, clean.fallen)
    world.begin(sequence)  # a solver that diverged without failing: the state is not finite after it
    state.SetFromVector(x)
    assert world.advance_to(0.0) == "the solver diverged: the state is not finite at t = 0.00 s"


def test_only_drake_failures_count_as_simulation_failures():
    from hlp_drake.systems.world.simulation import simulation_failure

    assert simulation_failure(RuntimeError("SAP failed\nmore")) == "SAP failed"
    assert simulation_failure(SystemExit("Failure at x.h:1 in f(): condition 'c' failed.")).startswith(
        "Failure at"
    )
    diverged = SystemExit("Failure at x.h:2897 in SetPositions(): condition 'AllFinite(q)' failed.")
    assert simulation_failure(diverged) == "the simulation diverged (the state turned non-finite)"
    with pytest.raises(SystemExit):
        simulation_failure(SystemExit(2))


def test_two_workers_give_the_same_outcomes_as_one(scene, trajectories):
    base = short(ControlSequence.from_trajectory(trajectories["line"], 0.5), 1.0)
    config = sto(scene, "reduced_model: true")
    noise = sample_base_noise(np.random.default_rng(0), base, config.sto.noise, 3)
    sequences = [base.with_base_velocity(v) for v in noise]
    local = [SceneRollouts(config).rollout(s) for s in sequences]  # a fresh set of worlds for each
    with RolloutPool(2) as pool:
        (single,) = pool.rollouts(config, sequences[:1])  # here: no worker started for it
        assert pool.startup_s == 0.0
        remote = pool.rollouts(config, sequences)  # a batch: on the workers, started for it
        assert pool.startup_s > 0
    assert single.cost == local[0].cost
    assert [o.cost for o in remote] == [o.cost for o in local]
    assert [o.asleep for o in remote] == [o.asleep for o in local] and all(o.asleep for o in local)


def test_a_pool_keeps_its_worlds_by_spec_until_it_is_closed(scene):
    with RolloutPool(1) as pool:
        kept = pool.world(sto(scene))
        assert pool.world(sto(scene)) is kept  # an equal spec: the same key, the same worlds
        assert pool.world(sto(scene, "samples: 3")) is not kept
    with RolloutPool(1) as other:  # worlds belong to their pool
        assert other.world(sto(scene)) is not kept


def test_a_rollout_spec_reads_back_from_its_yaml_as_a_worker_gets_it(scene):
    from hlp_drake.systems.low_level.sto.spec import RolloutSpec

    original = sto(scene, "samples: 3")
    again = RolloutSpec.from_yaml(original.yaml)
    assert again.yaml == original.yaml and again.key == original.key and again.world_key == original.world_key
    assert again.scene == original.scene and again.sto == original.sto
    assert sto(scene, "samples: 4").world_key == original.world_key  # the same world, another search
    assert spec(on(scene, "plant: {time_step: 0.005}")).world_key != original.world_key
