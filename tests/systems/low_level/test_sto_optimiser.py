"""The STO as a low-level planner: the optimiser's budgets, its alternatives, verification and the
displaced worlds; its planner (``StoPlanner``) and its Drake block."""

from __future__ import annotations

import dataclasses
from dataclasses import replace

import numpy as np
import pytest
from pydrake.trajectories import PiecewisePolynomial
from sto_support import on, short, spec, sto

from hlp_drake.errors import HlpError
from hlp_drake.scene.model import SceneObject
from hlp_drake.systems.low_level.control_sequence import ControlSequence
from hlp_drake.systems.low_level.protocol import LowLevelProblem
from hlp_drake.systems.low_level.sto.budget import Budget
from hlp_drake.systems.low_level.sto.config import PERCEIVED_CHECKS, StoConfig
from hlp_drake.systems.low_level.sto.optimiser import optimise
from hlp_drake.systems.low_level.sto.planner import StoPlanner
from hlp_drake.systems.low_level.sto.pool import RolloutPool
from hlp_drake.systems.low_level.system import StochasticTrajectoryOptimiser


def test_optimiser_is_seeded_monotone_and_stops_at_its_iteration_budget(scene, trajectories):
    config = sto(scene, "max_iterations: 2, samples: 2, update: mppi")
    initial = short(ControlSequence.from_trajectory(trajectories["line"], 0.5), 1.0)  # too short to reach
    with RolloutPool(1) as pool:
        first = optimise(config, initial, pool)
        second = optimise(config, initial, pool)
    assert not first.success and "after 2 iterations" in first.failure_reason
    assert first.iterations == 2 and first.rollouts == 1 + 2 * (2 + 1)  # mppi rolls its mean out too
    assert all(b <= a for a, b in zip(first.costs, first.costs[1:]))
    assert first.costs == second.costs
    np.testing.assert_array_equal(first.sequence.knots, second.sequence.knots)


def test_optimiser_respects_its_time_budget(scene, trajectories):
    config = sto(scene, "time_budget_s: 1.0e-3")
    initial = short(ControlSequence.from_trajectory(trajectories["line"], 0.5), 1.0)
    with RolloutPool(1) as pool:
        result = optimise(config, initial, pool)
    assert not result.success and result.iterations == 0 and result.rollouts == 1
    assert "time budget" in result.failure_reason


def test_optimiser_stops_at_its_rollout_budget_with_the_same_result_on_two_workers(scene, trajectories):
    assert StoConfig().time_budget_s == 0.0  # by default no wall-clock budget at all
    config = sto(scene, "samples: 2, max_iterations: 20, max_rollouts: 5")
    initial = short(ControlSequence.from_trajectory(trajectories["line"], 0.5), 1.0)  # too short to reach
    with RolloutPool(1) as pool:
        one = optimise(config, initial, pool)
    with RolloutPool(2) as pool:
        two = optimise(config, initial, pool)
    assert not one.success and one.rollouts == 5 and one.iterations == 2
    assert "rollout budget of 5 spent" in one.failure_reason
    assert (two.costs, two.rollouts, two.failure_reason) == (one.costs, one.rollouts, one.failure_reason)
    np.testing.assert_array_equal(two.sequence.knots, one.sequence.knots)


def test_a_failed_initial_rollout_goes_on_from_the_planners_first_passing_alternative(scene, trajectories):
    config = sto(scene, "max_iterations: 1, samples: 1, check_step: 0")  # no check on a finer model
    stuck = short(ControlSequence.from_trajectory(trajectories["line"], 0.5), 1.0)  # fails: too short
    reaching = ControlSequence.from_trajectory(trajectories["hlp"], 0.5)  # passes
    calls = []

    def alternatives():
        calls.append(1)
        return [stuck, reaching, reaching]

    with RolloutPool(1) as pool:
        passed = optimise(config, reaching, pool, alternatives=alternatives)
        assert passed.success and passed.start == 0 and passed.rollouts == 1 and not calls  # not needed
        # rolled out on the execution model: its own verification, nothing simulated again
        assert passed.verifications == 0 and passed.verify_s == 0.0
        assert passed.outcome.verification.cost == passed.outcome.cost
        reduced = sto(
            scene, "max_iterations: 1, samples: 1, reduced_model: true"
        )  # an approximation: verified
        checked = optimise(reduced, reaching, pool)
        assert checked.success and checked.verifications == 1 and checked.rejected == 0
        assert checked.outcome.verification.success and checked.outcome.verification.wall_s > 0
        assert checked.outcome.verification.wall_s <= checked.verify_s <= checked.optimise_s
        unverified = optimise(replace(reduced, sto=replace(reduced.sto, max_verifications=0)), reaching, pool)
        assert not unverified.success and "verifications ran out" in unverified.failure_reason
        assert unverified.verify_s == 0.0 and unverified.to_dict()["verify_s"] == 0.0
        result = optimise(config, stuck, pool, alternatives=alternatives)
        assert calls == [1]
        assert result.success and result.iterations == 0 and result.start == 2  # the first that passes
        assert result.rollouts == 1 + 3 and result.sequence is not stuck
        assert result.to_dict()["start"] == 2 and result.costs[-1] < result.costs[0]
        budget = Budget.of(config.sto)
        one = replace(budget, alternatives=1)  # only the first: it fails too, and costs no less
        capped = optimise(config, stuck, pool, alternatives=alternatives, budget=one)
        assert not capped.success and capped.start == 0 and capped.rollouts == 1 + 1 + 1
        none = replace(budget, alternatives=0)
        never = optimise(config, stuck, pool, alternatives=lambda: pytest.fail("called"), budget=none)
        assert never.rollouts == 1 + 1


def test_a_start_in_collision_fails_without_rollouts(scene, trajectories):
    blocker = SceneObject(
        name="Blocker",
        shape="box",
        x=float(scene.start[0]) + 0.03,
        y=float(scene.start[1]),
        size=(0.04, 0.16, 0.12),
    )  # wider than the open fingers
    blocked = dataclasses.replace(scene, obstacles=(*scene.obstacles, blocker))
    initial = short(ControlSequence.from_trajectory(trajectories["line"], 0.5), 1.0)
    with RolloutPool(1) as pool:
        result = optimise(spec(on(blocked, "planner: {low_level: {max_iterations: 1}}")), initial, pool)
    assert not result.success and result.rollouts == 0
    assert result.failure_reason == "the robot starts in collision with Blocker"


def test_optimiser_block_ports_and_cache(scene, trajectories):
    with RolloutPool(1) as pool:
        block = StochasticTrajectoryOptimiser(StoConfig(max_iterations=1), pool=pool)  # alone, by keywords
        assert [block.get_input_port(i).get_name() for i in range(block.num_input_ports())] == [
            "scene",
            "keyframes",
            "initial_trajectory",
            "alternative_trajectories",
        ]
        assert block.planner.kind == "sto" and block.planner.as_commanded(trajectories["hlp"]).num_steps > 1
        context = block.CreateDefaultContext()
        empty = block.get_result_output_port().Eval(context)
        assert not empty.success and empty.failure_reason == "no initial trajectory"
        block.GetInputPort("initial_trajectory").FixValue(context, trajectories["hlp"])
        with pytest.raises(RuntimeError, match="connect or fix its 'scene' input"):
            block.GetOutputPort("result").Eval(context)
        block.get_scene_input_port().FixValue(context, scene)
        result = block.GetOutputPort("result").Eval(context)
        trajectory = block.GetOutputPort("trajectory").Eval(context)
        assert block.GetOutputPort("result").Eval(context) is result  # cached
        assert result.success and result.iterations == 0  # the HLP initialisation already succeeds here
        assert isinstance(trajectory, PiecewisePolynomial)
        assert trajectory.end_time() == pytest.approx(trajectories["hlp"].end_time())
        block.GetInputPort("alternative_trajectories").FixValue(context, (trajectories["hlp"],))
        again = block.GetOutputPort("result").Eval(context)  # a new input value: optimised again
        assert again is not result and again.success and again.start == 0


def test_an_unreachable_target_fails_with_a_reason_and_no_rollouts(scene):
    from hlp_drake.systems.execution.run import plan_and_execute

    far = dataclasses.replace(scene.target, x=scene.table.length + 1.5)
    with RolloutPool(1) as pool:
        unreachable = on(dataclasses.replace(scene, target=far))  # (an invalid scene: built, not loaded)
        straight = dataclasses.replace(
            unreachable, planner=dataclasses.replace(unreachable.planner, initial="line")
        )
        result = plan_and_execute(straight, pool=pool)
    assert (
        not result.success
        and result.failure_reason.startswith("IK failed")
        and "Target" in result.failure_reason
    )
    assert result.rollouts == 0 and result.grasp_held is None


def test_displaced_scenes_move_every_object_by_about_sigma_and_are_seeded(scene):
    from hlp_drake.systems.world.uncertainty import displaced_scenes

    a, b = displaced_scenes(scene, 2, 0.001, 0.01), displaced_scenes(scene, 2, 0.001, 0.01)
    assert a == b and len(a) == 2 and a[0] != a[1]
    for moved in a:
        pairs = list(zip(scene.objects, moved.objects))
        assert all(o.name == m.name and o.size == m.size for o, m in pairs)
        offsets = np.array([np.hypot(m.x - o.x, m.y - o.y) for o, m in pairs])
        assert 0.0 < offsets.max() < 0.006  # a few sigma, every object displaced by a different amount
        assert len(set(np.round(offsets, 9))) == len(offsets)
    assert displaced_scenes(scene, 1, 0.0, 0.0) == [scene]


def test_a_verified_sequence_counts_only_if_it_passes_with_the_objects_displaced(scene, trajectories):
    reaching = ControlSequence.from_trajectory(trajectories["hlp"], 0.5)  # passes, verified too
    settings = "max_rollouts: 1, samples: 1, displaced_checks: 1, displaced_sigma: {}"
    with RolloutPool(2) as pool:
        kept = optimise(sto(scene, settings.format(0.001)), reaching, pool)
        moved = optimise(sto(scene, settings.format(0.05)), reaching, pool)  # the target 5 cm off and more
    assert kept.success and (kept.verifications, kept.displaced_checks, kept.rejected) == (1, 1, 0)
    assert kept.outcome.verification is not None and kept.to_dict()["displaced_checks"] == 1
    assert not moved.success and (moved.verifications, moved.displaced_checks, moved.rejected) == (1, 1, 1)
    assert "passed its verification, failed with the objects displaced (1 of 1)" in moved.failure_reason
    assert "rollout budget of 1 spent" in moved.failure_reason
    with pytest.raises(HlpError, match=r"planner\.low_level\.displaced_checks must be between 0 and 100"):
        on(scene, "planner: {low_level: {displaced_checks: -1}}")


def test_the_search_ends_once_its_verifications_are_spent_whatever_rollouts_are_left(scene, trajectories):
    reaching = ControlSequence.from_trajectory(trajectories["hlp"], 0.5)  # passes every rollout
    settings = (
        "max_rollouts: 40, samples: 2, max_verifications: 2, displaced_checks: 1,"
        " displaced_sigma: 0.05"  # every verified sequence fails with the objects displaced
    )
    with RolloutPool(2) as pool:
        result = optimise(sto(scene, settings), reaching, pool)
    assert not result.success and (result.verifications, result.rejected) == (2, 2)
    assert result.failure_reason.endswith("(verifications spent)") and result.rollouts < 40
    assert StoConfig().max_verifications == 8


def test_perceived_scenes_get_displaced_checks_unless_the_scenario_sets_them(scene, trajectories):
    assert Budget.of(StoConfig()).displaced_checks == 0
    assert Budget.of(StoConfig(), perceived=True).displaced_checks == PERCEIVED_CHECKS == 2
    assert Budget.of(StoConfig(displaced_checks=0), perceived=True).displaced_checks == 0
    assert Budget.of(StoConfig(displaced_checks=3)).displaced_checks == 3
    with RolloutPool(2) as pool:  # the STO made for a camera's scene
        planner = StoPlanner.of(StoConfig(max_rollouts=1, samples=1), pool=pool, perceived=True)
        result = planner.plan(LowLevelProblem(scene, None, trajectories["hlp"]))
    assert result.success and (result.verifications, result.displaced_checks) == (1, PERCEIVED_CHECKS)
