"""KeypointIk's reach across scenes and robots: far targets, deep tables, the iteration cap, a fixed arm."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from ik_support import CONFIG, ik_for, solve, through_gaps

from hlp_drake.planner.plan import HighLevelPlan, PlanKeypoint
from hlp_drake.scene.generators import generate_scene
from hlp_drake.scene.model import Scene, SceneObject, Table
from hlp_drake.systems.planning.ik import KeypointIk
from hlp_drake.systems.planning.keyframes import Keyframes
from hlp_drake.systems.world.robot_description import MOBILE_UR5, load_robot


def assert_reaches(keyframes: Keyframes, plan: HighLevelPlan, height: float) -> None:
    assert keyframes.ok, keyframes.failures
    for tcp, keypoint in zip(keyframes.tcp_positions, plan.keypoints):
        np.testing.assert_allclose(tcp, [*keypoint.position, height], atol=0.005)


@pytest.mark.parametrize(
    "kind, seed", [("gen1", 0), ("gen1", 1), ("gen1", 2), ("gen1", 3), ("gen1", 4), ("vr", 0)]
)
def test_ik_reaches_the_target_of_generated_and_vr_scenes(kind, seed):
    """The target keypoint (0.53-0.86 m deep on 0.70-0.80 m tables) is reached straight from the start
    and through the rows' gaps."""
    scene = generate_scene(kind, seed)
    system = ik_for(scene)
    target = PlanKeypoint("target", scene.target.position, element=scene.target.name)
    direct = HighLevelPlan(scene=scene.name, keypoints=(PlanKeypoint("start", scene.start), target))
    height = scene.table.height + CONFIG.ik.height
    for plan in (direct, through_gaps(scene, to_target=True)):
        assert_reaches(solve(system, plan), plan, height)


@pytest.mark.parametrize("kind, seed, objects", [("gen2", 17, 5), ("gen1", 41, None)])
def test_a_far_target_straight_from_the_start_is_reached_by_continuation(kind, seed, objects):
    """Targets 0.83 m (gen2 seed 17, 0.19 m to the side) and 0.86 m (gen1 seed 41) deep: from the
    start's folded arm the base stops at its bound and SNOPT ends at its iteration limit from every
    other seed; solving points along the straight tcp line first reaches them."""
    scene = generate_scene(kind, seed, objects)
    target = PlanKeypoint("target", scene.target.position, element=scene.target.name)
    direct = HighLevelPlan(scene=scene.name, keypoints=(PlanKeypoint("start", scene.start), target))
    height = scene.table.height + CONFIG.ik.height
    assert_reaches(solve(ik_for(scene), direct), direct, height)
    without = replace(CONFIG, ik=replace(CONFIG.ik, attempts=4))  # the seeds before the continuation
    failed = solve(ik_for(scene, without), direct)
    assert not failed.ok and "IK failed after 4 attempt(s)" in failed.failures[0]


@pytest.mark.parametrize("height", [0.70, 0.80])
def test_tcp_reaches_0_95_m_past_the_front_edge_and_the_edge_itself(height):
    """The riser puts the arm's mount at about table height: the horizontal gripper reaches 0.95 m deep
    into a 0.70 m and a 0.80 m high table, and comes back to its front edge."""
    scene = Scene(
        table=Table(length=1.05, width=1.0, height=height),
        start=(0.1, 0.0),
        target=SceneObject("target", "cylinder", 0.95, 0.0, (0.05, 0.05, 0.1)),
        name=f"reach-{height}",
    )
    system = ik_for(scene)
    plan = HighLevelPlan(
        scene=scene.name,
        keypoints=(
            PlanKeypoint("start", scene.start),
            PlanKeypoint("target", scene.target.position, element="target"),
            PlanKeypoint("gap", (0.0, 0.0), element="edge"),
        ),
    )
    keyframes = solve(system, plan)
    assert_reaches(keyframes, plan, height + CONFIG.ik.height)
    # The base stays outside the table's footprint.
    assert np.all(
        keyframes.positions[:, 0] + MOBILE_UR5.base.footprint[0] / 2.0 <= CONFIG.ik.base_under_table + 1e-6
    )


def test_the_default_iteration_cap_gives_the_keyframes_of_a_five_times_larger_one():
    """On gen2-7-5 SNOPT lingers at a converged point of one keypoint for hundreds of major
    iterations; stopping at ``ik.max_iterations`` (an iterate meeting every constraint counts)
    leaves every keyframe where 5x the iterations put it."""
    from hlp_drake.systems.planning.diagram import make_planning_diagram
    from hlp_drake.systems.world.scene_source import SCENE_PORT

    scene = generate_scene("gen2", 5, 7)

    def keyframes(max_iterations: int) -> Keyframes:
        scenario = replace(CONFIG, scene=scene, ik=replace(CONFIG.ik, max_iterations=max_iterations))
        diagram = make_planning_diagram(scenario)
        context = diagram.CreateDefaultContext()
        diagram.GetInputPort(SCENE_PORT).FixValue(context, scene)
        return diagram.GetOutputPort("keyframes").Eval(context)

    capped, longer = keyframes(CONFIG.ik.max_iterations), keyframes(5 * CONFIG.ik.max_iterations)
    assert CONFIG.ik.max_iterations == 100
    assert capped.ok and longer.ok and len(capped.keypoints) >= 6
    np.testing.assert_allclose(capped.positions, longer.positions, atol=1e-4)


def approach_angles(system: KeypointIk, keyframes: Keyframes, tcp_frame: str) -> np.ndarray:
    """Per keyframe, the angle between the approach axis (tcp +z) and world +x, degrees."""
    model = system.solver.planning_model
    context = model.plant.GetMyMutableContextFromRoot(model.diagram.CreateDefaultContext())
    tcp = model.plant.GetFrameByName(tcp_frame, model.robot)
    angles = []
    for q in keyframes.positions:
        model.plant.SetPositions(context, model.robot, q)
        axis = tcp.CalcPoseInWorld(context).rotation().matrix()[:, 2]
        angles.append(math.degrees(math.acos(np.clip(axis[0], -1.0, 1.0))))
    return np.array(angles)


def test_a_fixed_arms_approach_weight_keeps_its_hand_square_to_the_table():
    """The Panda's way through a gap, along a push and on to the target (gen1-5's): with no weight
    its step cost turns the hand to the tolerance's edge (20 degrees); its description's weight
    keeps it nearer +x at every keyframe."""
    panda = load_robot("panda")
    scene = generate_scene("gen1", 5, workspace=panda.workspace)
    plan = HighLevelPlan(
        scene=scene.name,
        keypoints=(
            PlanKeypoint("start", scene.start),
            *(
                PlanKeypoint("gap", p, row=1, element="0")
                for p in ((0.228, 0.0), (0.274, 0.01), (0.383, -0.1))
            ),
            PlanKeypoint("target", scene.target.position, element=scene.target.name),
        ),
    )
    assert panda.approach_weight > 0.0
    turned, square = (
        ik_for(scene, replace(CONFIG, robot=replace(panda, approach_weight=weight)))
        for weight in (0.0, panda.approach_weight)
    )
    loose, held = (solve(system, plan) for system in (turned, square))
    assert all(loose.success) and all(held.success)
    np.testing.assert_allclose(held.tcp_positions, loose.tcp_positions, atol=0.003)  # the same waypoints
    loose_angles, held_angles = (
        approach_angles(system, keyframes, panda.tcp_frame)
        for system, keyframes in ((turned, loose), (square, held))
    )
    assert loose_angles.max() > 19.0  # turned to the 20 degree tolerance (at the push's end)
    assert np.all(held_angles <= loose_angles + 0.5)
    assert held_angles.max() < loose_angles.max() - 4.0 and held_angles.mean() < 0.7 * loose_angles.mean()
