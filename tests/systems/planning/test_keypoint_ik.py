"""KeypointIk: plan keypoints -> IK keyframes -> a joint-space first-order-hold trajectory."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from ik_support import CONFIG, gap_centres, ik_for, solve, through_gaps
from pydrake.trajectories import PiecewisePolynomial

from hlp_drake.planner.plan import HighLevelPlan, PlanKeypoint
from hlp_drake.scene.generators import generate_scene
from hlp_drake.scene.model import Scene
from hlp_drake.systems.planning.ik import KeypointIk
from hlp_drake.systems.planning.keyframes import Keyframes
from hlp_drake.systems.world.robot_description import MOBILE_UR5
from hlp_drake.systems.world.start_pose import start_configuration
from hlp_drake.systems.world.world import make_world_diagram, world_plant


@pytest.fixture(scope="module")
def scene() -> Scene:
    return generate_scene("gen1", 11)


@pytest.fixture(scope="module")
def system(scene) -> KeypointIk:
    return ik_for(scene)


def evaluate(system: KeypointIk, plan: HighLevelPlan) -> tuple[Keyframes, PiecewisePolynomial]:
    context = system.CreateDefaultContext()
    system.get_input_port(0).FixValue(context, plan)
    keyframes = system.GetOutputPort("keyframes").Eval(context)
    trajectory = system.GetOutputPort("trajectory").Eval(context)
    return keyframes, trajectory


@pytest.fixture(scope="module")
def solved(system, scene):
    return evaluate(system, through_gaps(scene, to_target=False))


def test_ports(system):
    assert [system.get_input_port(i).get_name() for i in range(system.num_input_ports())] == [
        "plan",
        "alternatives",
    ]
    assert [system.get_output_port(i).get_name() for i in range(system.num_output_ports())] == [
        "keyframes",
        "trajectory",
        "alternative_trajectories",
    ]


def test_keyframes_put_the_tcp_on_every_waypoint(system, scene, solved):
    keyframes, _ = solved
    plan = through_gaps(scene, to_target=False)
    assert len(plan.keypoints) == 3  # start and one gap per row
    assert keyframes.ok, keyframes.failures
    assert keyframes.success == (True,) * 3 and keyframes.messages == ("",) * 3
    assert keyframes.positions.shape == (3, 11)
    # Forward kinematics on the world's own plant, independent of the IK's planning model.
    plant, robot = world_plant(make_world_diagram(replace(CONFIG, scene=scene)))
    context = plant.CreateDefaultContext()
    tcp = plant.GetFrameByName(MOBILE_UR5.tcp_frame, robot)
    height = scene.table.height + CONFIG.ik.height
    for q, waypoint in zip(keyframes.positions, plan.waypoints):
        plant.SetPositions(context, robot, q)
        X = tcp.CalcPoseInWorld(context)
        np.testing.assert_allclose(X.translation(), [*waypoint, height], atol=0.01)
        approach = X.rotation().matrix()[:, 2]
        assert math.acos(np.clip(approach[0], -1, 1)) <= CONFIG.ik.approach_tolerance + 1e-6
        assert abs(X.rotation().matrix()[2, 1]) <= math.sin(CONFIG.ik.roll_tolerance) + 1e-6
    np.testing.assert_allclose(keyframes.tcp_positions[:, :2], plan.waypoints, atol=0.01)


def test_keyframes_respect_joint_limits_and_keep_the_gripper_open(system, solved):
    keyframes, _ = solved
    plant = system.solver.planning_model.plant
    lower, upper = plant.GetPositionLowerLimits(), plant.GetPositionUpperLimits()
    assert np.all(keyframes.positions >= lower - 1e-6) and np.all(keyframes.positions <= upper + 1e-6)
    np.testing.assert_allclose(
        keyframes.positions[:, 9:], np.tile(system.solver.start[9:], (3, 1)), atol=1e-9
    )
    assert np.all(keyframes.positions[:, 0] < 0.0)  # the arm's mount stays in front of the table


def test_trajectory_starts_at_the_start_and_passes_through_the_keyframes(system, scene, solved):
    keyframes, trajectory = solved
    model = system.solver.planning_model
    start = start_configuration(scene, CONFIG.ik, model.plant, model.robot)
    assert trajectory.start_time() == 0.0
    np.testing.assert_allclose(trajectory.value(0.0).ravel(), start, atol=1e-12)
    np.testing.assert_allclose(keyframes.positions[0], start, atol=1e-12)  # the "start" keypoint
    breaks = trajectory.get_segment_times()
    assert len(breaks) == len(keyframes.positions)  # start + the two gaps; no duplicated knot
    for t, q in zip(breaks, keyframes.positions):  # the gripper aside (closed at the gaps)
        np.testing.assert_allclose(trajectory.value(t).ravel()[:9], q[:9], atol=1e-9)
    # Timed by the tcp speed: no segment is shorter than its tcp path over tcp_speed.
    for i in range(1, len(breaks)):
        path = np.linalg.norm(keyframes.tcp_positions[i] - keyframes.tcp_positions[i - 1])
        assert (
            breaks[i] - breaks[i - 1]
            >= max(path / CONFIG.motion.tcp_speed, CONFIG.motion.min_segment_duration) - 1e-9
        )
    # A first-order hold: straight lines in joint space between keyframes.
    middle = 0.5 * (breaks[0] + breaks[1])
    np.testing.assert_allclose(
        trajectory.value(middle).ravel(),
        0.5 * (trajectory.value(breaks[0]) + trajectory.value(breaks[1])).ravel(),
        atol=1e-9,
    )


def fingers(trajectory: PiecewisePolynomial, t: float) -> np.ndarray:
    return trajectory.value(t).ravel()[9:]


def test_gripper_closes_among_the_obstacles_and_opens_before_the_target(system, scene):
    """Closed from the first gap on (closing on the way there), open again in place at the last gap
    before sliding onto the target (the plan has no approach keypoint); open throughout when
    ``motion.closed_among_obstacles`` is off."""
    plan = through_gaps(scene, to_target=True)
    keyframes, trajectory = evaluate(system, plan)
    assert keyframes.ok, keyframes.failures
    breaks = trajectory.get_segment_times()
    assert len(breaks) == len(plan.keypoints) + 1  # the opening in place is a knot of its own
    np.testing.assert_allclose(fingers(trajectory, 0.0), [MOBILE_UR5.gripper_open] * 2)
    assert 0.0 < fingers(trajectory, 0.5 * breaks[1])[0] < MOBILE_UR5.gripper_open  # closing on the way
    for t in breaks[1:3]:
        np.testing.assert_allclose(fingers(trajectory, t), [MOBILE_UR5.gripper_closed] * 2)
    np.testing.assert_allclose(trajectory.value(breaks[3])[:9], trajectory.value(breaks[2])[:9])  # in place
    for t in breaks[3:]:
        np.testing.assert_allclose(fingers(trajectory, t), [MOBILE_UR5.gripper_open] * 2)
    # The fingers' speed limit times the pace: no faster than the trajectory allows for any joint.
    assert (
        breaks[3] - breaks[2] >= MOBILE_UR5.gripper_open / (CONFIG.motion.joint_speed_fraction * 0.075) - 1e-9
    )

    config = replace(CONFIG, motion=replace(CONFIG.motion, closed_among_obstacles=False))
    _, open_all = evaluate(ik_for(scene, config), plan)
    assert len(open_all.get_segment_times()) == len(plan.keypoints)
    for t in open_all.get_segment_times():
        np.testing.assert_allclose(fingers(open_all, t), [MOBILE_UR5.gripper_open] * 2)


def test_gripper_opens_on_the_way_to_an_approach_keypoint(system, scene):
    gaps = through_gaps(scene, to_target=False)
    x, y = scene.target.position
    approach = PlanKeypoint("approach", (x - 0.08, y), element=scene.target.name)
    target = PlanKeypoint("target", scene.target.position, element=scene.target.name)
    plan = HighLevelPlan(scene=scene.name, keypoints=(*gaps.keypoints, approach, target))
    keyframes, trajectory = evaluate(system, plan)
    assert keyframes.ok, keyframes.failures
    breaks = trajectory.get_segment_times()
    assert len(breaks) == len(plan.keypoints)  # no knot added
    np.testing.assert_allclose(fingers(trajectory, breaks[2]), [MOBILE_UR5.gripper_closed] * 2)
    assert 0.0 < fingers(trajectory, 0.5 * (breaks[2] + breaks[3]))[0] < MOBILE_UR5.gripper_open
    for t in breaks[3:]:
        np.testing.assert_allclose(fingers(trajectory, t), [MOBILE_UR5.gripper_open] * 2)


def test_unreachable_waypoint_is_reported_for_that_keypoint(system, scene):
    good = through_gaps(scene, to_target=False)
    far = PlanKeypoint("target", (scene.table.length + 3.0, 0.0), element=scene.target.name)
    plan = HighLevelPlan(scene=scene.name, keypoints=(*good.keypoints, far))
    keyframes, trajectory = evaluate(system, plan)
    assert not keyframes.ok
    assert keyframes.success == (True, True, True, False)
    assert keyframes.messages[:3] == ("", "", "")
    assert "keypoint 3" in keyframes.messages[3] and "target" in keyframes.messages[3]
    assert "IK failed" in keyframes.messages[3]
    assert keyframes.failures == [keyframes.messages[3]]
    # The trajectory skips the failed keyframe and ends at the last good one (the gripper closed).
    np.testing.assert_allclose(
        trajectory.value(trajectory.end_time()).ravel()[:9], keyframes.positions[2][:9], atol=1e-9
    )


def test_a_plan_with_an_unreachable_keypoint_gives_way_to_its_first_reachable_alternative(system, scene):
    """A keypoint the robot cannot reach fails the plan's IK; the first of the alternatives whose
    IK succeeds takes its place (the rest stay the optimiser's), and the failures it replaced are
    kept. With no reachable alternative, or a plan-level problem, the plan's own keyframes stand."""
    good = through_gaps(scene, to_target=True)
    far = PlanKeypoint("gap", (scene.table.length + 3.0, 0.0), row=0, element="0")
    unreachable = replace(good, keypoints=(*good.keypoints[:2], far, *good.keypoints[2:]))
    other = through_gaps(scene, to_target=False)
    context = system.CreateDefaultContext()
    system.GetInputPort("plan").FixValue(context, unreachable)
    system.GetInputPort("alternatives").FixValue(context, (unreachable, good, other))
    keyframes = system.GetOutputPort("keyframes").Eval(context)
    trajectory = system.GetOutputPort("trajectory").Eval(context)
    alone, alone_trajectory = evaluate(system, good)
    assert keyframes.ok and keyframes.candidate == 2
    assert keyframes.keypoints == good.keypoints
    assert len(keyframes.replaced) == 1 and "keypoint 2 (gap 0)" in keyframes.replaced[0]
    np.testing.assert_allclose(keyframes.positions, alone.positions, atol=1e-9)
    np.testing.assert_allclose(
        trajectory.vector_values(trajectory.get_segment_times()),
        alone_trajectory.vector_values(alone_trajectory.get_segment_times()),
        atol=1e-9,
    )
    rest = system.GetOutputPort("alternative_trajectories").Eval(context)
    _, other_trajectory = evaluate(system, other)
    assert len(rest) == 1  # the unreachable one has none, the one taken is not offered again
    np.testing.assert_allclose(rest[0].get_segment_times(), other_trajectory.get_segment_times())

    system.GetInputPort("alternatives").FixValue(context, (unreachable,))
    failed = system.GetOutputPort("keyframes").Eval(context)
    assert not failed.ok and failed.candidate == 0 and failed.replaced == ()
    assert failed.failures == list(keyframes.replaced)
    wrong = replace(unreachable, scene="another scene")
    system.GetInputPort("plan").FixValue(context, wrong)
    system.GetInputPort("alternatives").FixValue(context, (good,))
    refused = system.GetOutputPort("keyframes").Eval(context)
    assert not refused.ok and refused.candidate == 0 and "another scene" in refused.problems[0]


def test_a_reachable_plan_leaves_the_alternatives_unplanned():
    """In the planning diagram the transfer's alternatives are made only when asked for: a plan
    whose IK succeeds does not ask (nor does its trajectory)."""
    from hlp_drake.systems.planning.diagram import make_planning_diagram
    from hlp_drake.systems.world.scene_source import SCENE_PORT

    diagram = make_planning_diagram(CONFIG)
    context = diagram.CreateDefaultContext()
    diagram.GetInputPort(SCENE_PORT).FixValue(context, CONFIG.scene)
    keyframes = diagram.GetOutputPort("keyframes").Eval(context)
    diagram.GetOutputPort("trajectory").Eval(context)
    transfer = diagram.GetSubsystemByName("robot_plan_transfer")
    alternatives = transfer.get_robot_alternatives_output_port()
    assert keyframes.ok and keyframes.candidate == 0
    assert alternatives.cache_entry().is_out_of_date(transfer.GetMyContextFromRoot(context))


def test_an_unreachable_lifted_transit_is_left_out_and_the_way_goes_straight_on(system, scene):
    """A transit waypoint the arm cannot reach (over the table close before a fixed arm's pedestal)
    is the robot's own addition: the trajectory goes without it; any other keypoint is needed."""
    good = through_gaps(scene, to_target=False).keypoints
    far = (scene.table.length + 3.0, 0.0)
    lifted = PlanKeypoint("transit", far, row=0, element="0", height=0.3)
    keyframes, trajectory = evaluate(system, HighLevelPlan(scene=scene.name, keypoints=(*good, lifted)))
    assert keyframes.ok and keyframes.failures == []
    assert keyframes.success == (True, True, True, False)
    assert keyframes.skipped == [keyframes.messages[3]] and "transit" in keyframes.messages[3]
    np.testing.assert_allclose(
        trajectory.value(trajectory.end_time()).ravel()[:9], keyframes.positions[2][:9], atol=1e-9
    )
    needed = PlanKeypoint("gap", far, row=0, element="0")
    keyframes, _ = evaluate(system, HighLevelPlan(scene=scene.name, keypoints=(*good, needed)))
    assert not keyframes.ok and keyframes.skipped == [] and keyframes.failures == [keyframes.messages[3]]


def test_outputs_are_cached_until_the_plan_changes(system, scene):
    context = system.CreateDefaultContext()
    port = system.get_input_port(0)
    port.FixValue(context, through_gaps(scene, to_target=False))
    keyframes = system.GetOutputPort("keyframes")
    first = keyframes.Eval(context)
    trajectory = system.GetOutputPort("trajectory").Eval(context)
    assert keyframes.Eval(context) is first and system.GetOutputPort("trajectory").Eval(context) is trajectory
    shorter = HighLevelPlan(scene=scene.name, keypoints=through_gaps(scene, to_target=False).keypoints[:2])
    port.FixValue(context, shorter)
    assert len(keyframes.Eval(context).positions) == 2
    assert system.num_abstract_states() == 0 and system.num_discrete_state_groups() == 0  # only Drake's cache


def test_alternative_trajectories_are_solved_only_when_asked_for_and_like_the_plan(system, scene):
    context = system.CreateDefaultContext()
    port = system.GetOutputPort("alternative_trajectories")
    main, other = through_gaps(scene, to_target=True), through_gaps(scene, to_target=False)
    system.GetInputPort("plan").FixValue(context, main)
    system.GetInputPort("alternatives").FixValue(
        context, (other, HighLevelPlan(scene=scene.name, keypoints=(), reason="no plan"), main)
    )
    trajectory = system.GetOutputPort("trajectory").Eval(context)
    assert port.cache_entry().is_out_of_date(
        context
    )  # the alternatives are not solved for the plan's trajectory
    alternatives = port.Eval(context)
    assert len(alternatives) == 2  # the plan-less one has no trajectory
    assert not port.cache_entry().is_out_of_date(context) and port.Eval(context) is alternatives  # cached
    _, expected = evaluate(system, other)
    for got, want in ((alternatives[0], expected), (alternatives[1], trajectory)):
        np.testing.assert_allclose(got.get_segment_times(), want.get_segment_times())
        np.testing.assert_allclose(
            got.vector_values(got.get_segment_times()),
            want.vector_values(want.get_segment_times()),
            atol=1e-9,
        )


def test_no_plan_and_wrong_scene_are_problems_not_successes(system, scene):
    keyframes, trajectory = evaluate(system, HighLevelPlan(scene=scene.name, keypoints=(), reason="no gap"))
    assert not keyframes.ok and "no gap" in keyframes.problems[0]
    np.testing.assert_allclose(
        trajectory.value(trajectory.end_time()).ravel(), system.solver.start
    )  # holds the start
    other = HighLevelPlan(scene="another-scene", keypoints=through_gaps(scene, to_target=False).keypoints)
    keyframes, _ = evaluate(system, other)
    assert not keyframes.ok and "another-scene" in keyframes.problems[0]
    default_context = system.CreateDefaultContext()  # the port's model value: no plan yet
    assert not system.GetOutputPort("keyframes").Eval(default_context).ok


def test_start_gap_target_plan_on_gen1_succeeds(system, scene):
    keyframes, _ = evaluate(system, through_gaps(scene, to_target=True))
    assert keyframes.ok, keyframes.failures
    height = scene.table.height + CONFIG.ik.height
    np.testing.assert_allclose(keyframes.tcp_positions[-1], [*scene.target.position, height], atol=0.005)


def test_transit_keypoints_are_reached_at_their_height_and_timed_at_the_transit_speed(system, scene):
    gap = gap_centres(scene)[0]
    height = 0.25
    plan = HighLevelPlan(
        scene=scene.name,
        keypoints=(
            PlanKeypoint("start", scene.start),
            PlanKeypoint("transit", scene.start, height=height),
            PlanKeypoint("transit", gap, height=height),
            PlanKeypoint("gap", gap, row=0, element="0"),
        ),
    )
    keyframes, trajectory = evaluate(system, plan)
    assert keyframes.ok, keyframes.failures
    z = keyframes.tcp_positions[:, 2] - scene.table.height
    np.testing.assert_allclose(z, [CONFIG.ik.height, height, height, CONFIG.ik.height], atol=0.005)
    np.testing.assert_allclose(keyframes.tcp_positions[1:3, :2], [scene.start, gap], atol=0.005)
    # Segments to, between and from transit waypoints may go at the transit speed, not slower.
    breaks = trajectory.get_segment_times()
    paths = np.linalg.norm(np.diff(keyframes.tcp_positions, axis=0), axis=1)
    slow = [max(p / CONFIG.motion.tcp_speed, CONFIG.motion.min_segment_duration) for p in paths]
    assert any(d < s - 1e-3 for d, s in zip(np.diff(breaks), slow))
    for d, p in zip(np.diff(breaks), paths):
        assert d >= p / CONFIG.motion.transit_speed - 1e-9


def test_keyframes_keep_the_robot_clear_of_itself(system, scene, solved):
    """The IK's distance constraint includes the robot's own links (all but adjacent ones)."""
    keyframes, _ = solved
    model = system.solver.planning_model
    robot = set(model.robot_geometries())
    context = system.solver.new_context()
    for q in keyframes.positions:
        model.plant.SetPositions(system.solver.plant_context(context), model.robot, q)
        query = model.scene_graph.get_query_output_port().Eval(
            model.scene_graph.GetMyContextFromRoot(context)
        )
        pairs = [
            p
            for p in query.ComputeSignedDistancePairwiseClosestPoints(0.05)
            if p.id_A in robot and p.id_B in robot
        ]
        assert pairs, "the robot's self pairs should be checked"
        assert min(p.distance for p in pairs) >= CONFIG.ik.table_clearance - 1e-4


def test_a_persons_plan_wired_straight_into_ik_is_refused_not_executed(system):
    """A person's "move" keypoints are the obstacles' centres; only RobotPlanTransfer's plan is solved."""
    from hlp_drake.learners.bundled import default_models
    from hlp_drake.planner import plan as human_plan
    from hlp_drake.systems.planning.transfer import gripper_geometry
    from hlp_drake.transfer.push import robot_plan
    from hlp_drake.transfer.rules import push_rules

    scene = generate_scene("gen1", 3)
    person = human_plan(scene, default_models())
    assert any(k.action == "move" for k in person.keypoints)
    system = ik_for(scene)
    refused = solve(system, person)
    assert not refused.ok and "RobotPlanTransfer" in refused.problems[0]
    robot = robot_plan(person, scene, push_rules(CONFIG.transfer, gripper_geometry()))
    assert solve(system, robot).ok and person.details.get("robot_plan") is None
