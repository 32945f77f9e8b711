"""The push transfer (``RobotPlanTransfer``, ``robot_plan``): the human-like plan to the pushing robot's
waypoints, and the planning diagram's initialiser."""

from __future__ import annotations

from dataclasses import replace
from itertools import pairwise

import numpy as np
import pytest
from human_plans import GEN1_19, GEN1_27, GEN2_9_12, GEN2_9_39, GEN2_9_39_NEXT, human_plan

from hlp_drake.learners.bundled import default_models
from hlp_drake.planner import plan
from hlp_drake.scene.generators import generate_scene
from hlp_drake.systems.planning.diagram import make_planning_diagram
from hlp_drake.systems.planning.transfer import gripper_geometry
from hlp_drake.systems.scenario import Scenario
from hlp_drake.taskspace import DIRECTION_VECTORS, TaskSpace
from hlp_drake.transfer.push import ROBOT_ACTIONS, robot_alternatives, robot_plan
from hlp_drake.transfer.rules import TransferConfig, push_rules

RULES = push_rules(TransferConfig(), gripper_geometry())


def test_push_transfer_puts_the_tcp_behind_the_obstacle():
    scene = generate_scene("vr", 0)
    human = plan(scene, default_models())
    robot = robot_plan(human, scene, RULES)
    space = TaskSpace(scene)
    assert [k.action for k in robot.keypoints if k.action != "transit"] == [k.action for k in human.keypoints]
    assert {k.action for k in robot.keypoints} <= set(ROBOT_ACTIONS)
    lifted = max(o.size[2] for o in scene.objects) + 0.07
    transits = [i for i, k in enumerate(robot.keypoints) if k.action == "transit"]
    for i in transits[1::2]:  # lifted above the previous waypoint, then above the next one
        before, up, over, after = robot.keypoints[i - 2 : i + 2]
        assert (up.position, over.position) == (before.position, after.position)
        assert up.height == over.height == pytest.approx(lifted)
    for k in robot.keypoints:
        if k.action == "move":
            assert k.height is None
            rect, unit = space.rects[k.element], np.array(DIRECTION_VECTORS[k.direction], float)
            assert k.direction not in ("BB", "BL", "BR")  # the robot only pushes away or sideways
            # The push starts outside the obstacle, on the side opposite the push.
            offset = np.subtract(k.position, rect.center)
            assert offset @ unit < 0
            assert not rect.contains(np.array([k.position]))[0]


def test_robot_alternatives_are_the_next_distinct_candidates_in_rank_order():
    scene = generate_scene("gen2", 39, 9)
    human = human_plan(scene, GEN2_9_39, GEN2_9_39_NEXT)
    chosen = robot_plan(human, scene, RULES)
    candidates = [
        robot_plan(replace(human, keypoints=c.keypoints), scene, RULES).keypoints for c in human.alternatives
    ]
    alternatives = robot_alternatives(human, scene, RULES, 3)
    assert len(alternatives) == 3 and all(a.ok for a in alternatives)
    found = [a.keypoints for a in alternatives]
    assert len({chosen.keypoints, *found}) == 4  # distinct from the chosen plan and from each other
    ranks = [candidates.index(k) for k in found]
    assert ranks == sorted(ranks)  # best first, the first of equal robot plans
    assert all(k in (chosen.keypoints, *found) for k in candidates[: ranks[-1]])  # none skipped
    assert robot_alternatives(human, scene, RULES, 1) == alternatives[:1]
    assert robot_alternatives(human, scene, RULES, 0) == ()
    assert robot_alternatives(replace(human, keypoints=(), reason="no plan"), scene, RULES, 3) == ()


def test_planning_diagram_swaps_the_initialiser_block():
    scene = generate_scene("vr", 2)
    for initial, expected in (("hlp", None), ("line", ["start", "target"])):
        diagram = make_planning_diagram(Scenario(scene=scene).updated(f"planner: {{initial: {initial}}}"))
        assert diagram.HasSubsystemNamed(f"{initial}_planner")
        context = diagram.CreateDefaultContext()
        diagram.GetInputPort("scene").FixValue(context, scene)
        actions = [k.action for k in diagram.GetOutputPort("plan").Eval(context).keypoints]
        assert actions[0] == "start" and actions[-1] == "target"
        if expected:
            assert actions == expected
        keyframes = diagram.GetOutputPort("keyframes").Eval(context)
        assert len(keyframes.success) == len(actions)


def test_pushes_stop_short_of_the_table_edge_and_the_other_objects():
    from hlp_drake.transfer.push import push_travel

    EDGE_MARGIN, OBJECT_MARGIN = RULES.edge_margin, RULES.object_margin

    scene = generate_scene("gen1", 13)
    space = TaskSpace(scene)
    x_min, y_min, x_max, y_max = scene.table.bounds
    for name in scene_obstacle_names(scene):
        rect = space.rects[name]
        for unit in (np.array([0.0, 1.0]), np.array([0.0, -1.0]), np.array([1.0, 0.0])):
            travel = push_travel(RULES, space, scene, name, unit, 1.0)
            assert 0.0 <= travel < 1.0  # a 1 m push never fits on these tables
            dx, dy = travel * unit
            assert x_min + EDGE_MARGIN <= rect.x_min + dx and rect.x_max + dx <= x_max - EDGE_MARGIN
            assert y_min + EDGE_MARGIN <= rect.y_min + dy and rect.y_max + dy <= y_max - EDGE_MARGIN
            for other, r in space.rects.items():
                if other != name:
                    apart = (
                        rect.x_min + dx >= r.x_max + OBJECT_MARGIN
                        or r.x_min >= rect.x_max + dx + OBJECT_MARGIN
                        or rect.y_min + dy >= r.y_max + OBJECT_MARGIN
                        or r.y_min >= rect.y_max + dy + OBJECT_MARGIN
                    )
                    assert apart or travel == 0.0, (name, other, travel)
    # Unobstructed, the push goes as far as wanted.
    lone = scene_with_one_obstacle(scene)
    lone_space = TaskSpace(lone)
    assert push_travel(
        RULES, lone_space, lone, lone.obstacles[0].name, np.array([0.0, 1.0]), 0.02
    ) == pytest.approx(0.02)


def test_pushes_stop_short_of_where_earlier_pushes_left_the_other_objects():
    from hlp_drake.taskspace import Rect
    from hlp_drake.transfer.push import push_travel

    OBJECT_MARGIN = RULES.object_margin

    scene = generate_scene("gen1", 13)
    space = TaskSpace(scene)
    name, other = scene_obstacle_names(scene)[:2]
    rect = space.rects[name]
    unit = np.array([0.0, 1.0])
    # Another object moved to 5 cm beyond the pushed one's left face: the push stops 1 cm short of it.
    moved = dict(space.rects)
    moved[other] = Rect(rect.x_min, rect.y_max + 0.05, rect.x_max, rect.y_max + 0.10)
    travel = push_travel(RULES, space, scene, name, unit, 0.2, footprints=moved)
    assert (
        travel == pytest.approx(0.05 - OBJECT_MARGIN, abs=0.005 + 1e-9)
        and travel < 0.05 - OBJECT_MARGIN + 1e-9
    )
    # With every other object pushed far away, nothing but the table's edge limits it.
    cleared = {n: (r if n == name else Rect(-10.0, -10.0, -9.9, -9.9)) for n, r in space.rects.items()}
    assert push_travel(RULES, space, scene, name, unit, 0.2, footprints=cleared) >= push_travel(
        RULES, space, scene, name, unit, 0.2
    )


def scene_obstacle_names(scene):
    return [o.name for o in scene.obstacles]


def scene_with_one_obstacle(scene):
    from dataclasses import replace

    obstacle = replace(scene.obstacles[0], x=scene.table.length / 2, y=0.0)
    target = replace(scene.target, x=scene.table.length * 0.85, y=0.0)
    return replace(scene, obstacles=(obstacle,), target=target)


def test_a_push_with_no_room_to_move_the_obstacle_is_left_out():
    from hlp_drake.transfer.push import _robot_direction, _unit, _wanted, push_travel

    MIN_PUSH_TRAVEL = RULES.min_push_travel

    # gen1 seed 27: the person's plan moves FailOnTouchObstacleMed back-left (for the robot a push
    # to the left), then pushes FailOnTouchObstacleLong-1 to the right; the first push has no room,
    # so the robot plan leaves it out and keeps the second.
    scene = generate_scene("gen1", 27)
    space = TaskSpace(scene)
    human = human_plan(scene, GEN1_27)
    robot = robot_plan(human, scene, RULES)
    moves = [(k.element, k.direction) for k in human.keypoints if k.action == "move"]
    assert moves == [("FailOnTouchObstacleMed", "BL"), ("FailOnTouchObstacleLong-1", "RR")]
    name = moves[0][0]
    direction = _robot_direction(RULES, space, scene, name, moves[0][1])
    wanted = _wanted(space, name, direction)
    assert wanted > MIN_PUSH_TRAVEL > push_travel(RULES, space, scene, name, _unit(direction), wanted)
    pushes = [k for k in robot.keypoints if k.action in ("move", "release")]
    assert [(k.action, k.element) for k in pushes] == [("move", moves[1][0]), ("release", moves[1][0])]
    assert np.hypot(*np.subtract(pushes[1].position, pushes[0].position)) >= MIN_PUSH_TRAVEL


def test_an_obstacle_already_near_an_edge_can_be_pushed_along_it_but_not_towards_it():
    from hlp_drake.transfer.push import push_travel

    EDGE_MARGIN = RULES.edge_margin

    scene = generate_scene("gen1", 13)
    lone = scene_with_one_obstacle(scene)
    obstacle = lone.obstacles[0]
    half = TaskSpace(lone).rects[obstacle.name].width / 2
    y_max = lone.table.bounds[3]
    near = replace(
        lone, obstacles=(replace(obstacle, y=y_max - half - EDGE_MARGIN / 2),)
    )  # 1.5 cm from the edge
    space = TaskSpace(near)
    assert push_travel(RULES, space, near, obstacle.name, np.array([1.0, 0.0]), 0.05) == pytest.approx(0.05)
    assert push_travel(RULES, space, near, obstacle.name, np.array([0.0, 1.0]), 0.05) == 0.0
    assert push_travel(RULES, space, near, obstacle.name, np.array([0.0, -1.0]), 0.05) == pytest.approx(0.05)


def test_a_backward_move_becomes_the_sideways_push_that_clears_the_corridor():
    from hlp_drake.transfer.push import _robot_direction

    scene = generate_scene("gen1", 14)
    space = TaskSpace(scene)
    # Long lies right of the start-target line (y = 0) with Short close on its right: pushed right it
    # moves 4 cm out of the corridor, pushed left it would cross the line. Both count as backward.
    assert scene.start[1] == scene.target.y == 0.0
    long = space.rects["FailOnTouchObstacleLong"]
    assert long.center[1] < 0.0 < long.y_max
    for direction in ("BL", "BR", "BB"):
        assert _robot_direction(RULES, space, scene, "FailOnTouchObstacleLong", direction) == "RR"
    # On the left of the line, with room on both sides, it goes left whatever the person's side.
    assert {
        _robot_direction(RULES, space, scene, "FailOnTouchObstacleMed", d) for d in ("BL", "BR", "BB")
    } == {"LL"}
    # Forward and sideways moves are kept.
    assert _robot_direction(RULES, space, scene, "FailOnTouchObstacleLong", "LL") == "LL"
    assert _robot_direction(RULES, space, scene, "FailOnTouchObstacleLong", "FR") == "FR"


def test_transit_goes_over_the_objects_where_the_arm_can_come_down():
    from hlp_drake.planner.plan import PlanKeypoint
    from hlp_drake.taskspace import Rect
    from hlp_drake.transfer.push import transit

    ARM_SHADOW_LENGTH = RULES.arm_shadow_length

    previous = PlanKeypoint("release", (0.30, -0.20), row=0, element="a")
    push = PlanKeypoint("move", (0.60, 0.20), row=1, element="b", direction="RR")
    # Nothing under the arm at the push start: up, across, and straight down onto it.
    beside = [Rect(0.10, -0.50, 0.15, -0.40), Rect(0.40, 0.29, 0.45, 0.35), Rect(0.62, 0.15, 0.70, 0.25)]
    up, over = transit(RULES, previous, push, 0.25, beside)
    assert (up.position, over.position) == (previous.position, push.position)
    assert up.action == over.action == "transit" and up.height == over.height == 0.25
    assert (over.row, over.element) == (push.row, push.element)
    # An object under the wrist or the palm there: no transit, the push start is reached at push height.
    assert transit(RULES, previous, push, 0.25, [*beside, Rect(0.40, 0.25, 0.45, 0.30)]) == []
    assert (
        transit(
            RULES,
            previous,
            push,
            0.25,
            [Rect(0.60 - ARM_SHADOW_LENGTH - 0.05, 0.1, 0.60 - ARM_SHADOW_LENGTH + 0.01, 0.3)],
        )
        == []
    )
    assert (
        len(
            transit(
                RULES,
                previous,
                push,
                0.25,
                [Rect(0.60 - ARM_SHADOW_LENGTH - 0.05, 0.1, 0.60 - ARM_SHADOW_LENGTH - 0.01, 0.3)],
            )
        )
        == 2
    )


def test_a_way_that_would_pass_over_an_object_goes_over_it():
    from hlp_drake.taskspace import Rect
    from hlp_drake.transfer.push import crosses, transit_height

    PATH_CLEARANCE = RULES.path_clearance

    box = Rect(0.40, 0.00, 0.50, 0.10)
    assert crosses(RULES, (0.30, 0.05), (0.60, 0.05), [box])  # straight through
    assert crosses(RULES, (0.30, 0.10 + PATH_CLEARANCE - 0.005), (0.60, 0.10 + PATH_CLEARANCE - 0.005), [box])
    assert not crosses(
        RULES, (0.30, 0.10 + PATH_CLEARANCE + 0.005), (0.60, 0.10 + PATH_CLEARANCE + 0.005), [box]
    )
    assert not crosses(RULES, (0.30, 0.05), (0.60, 0.05), [])
    # gen2 seed 12, 9 obstacles: from where obstacle_4's push ends, the way to the next gap would
    # sweep the gripper through obstacle_5 at push height; the robot plan goes over it instead.
    scene = generate_scene("gen2", 12, 9)
    space = TaskSpace(scene)
    keypoints = robot_plan(human_plan(scene, GEN2_9_12), scene, RULES).keypoints
    i = next(i for i, k in enumerate(keypoints) if k.action == "release" and k.element == "obstacle_4")
    release, up, over, gap = keypoints[i : i + 4]
    assert crosses(RULES, release.position, gap.position, [space.rects["obstacle_5"]])
    assert (up.action, over.action, gap.action) == ("transit", "transit", "gap")
    assert (up.position, over.position) == (release.position, gap.position)
    assert up.height == over.height == pytest.approx(transit_height(RULES, scene))


def test_a_push_that_would_leave_the_obstacle_in_the_way_goes_another_way():
    from hlp_drake.transfer.push import chosen_push, crosses, robot_push

    WAY_CLEARANCE = RULES.way_clearance

    # gen1 seed 19: the person moves FailOnTouchObstacleLong-1 forwards, over the table; pushed
    # forwards it would end up across the way to the target (and shove the target off the table).
    scene = generate_scene("gen1", 19)
    space = TaskSpace(scene)
    human = human_plan(scene, GEN1_19)
    i = next(i for i, k in enumerate(human.keypoints) if k.action == "move")
    move, rest = human.keypoints[i], human.keypoints[i + 1 :]
    assert (move.element, move.direction) == ("FailOnTouchObstacleLong-1", "FF")
    ways = [k.position for k in rest if k.action in ("gap", "target")]

    def in_the_way(push):
        points = [push.end, *ways]
        return any(
            crosses(RULES, a, b, [push.footprint], clearance=WAY_CLEARANCE) for a, b in pairwise(points)
        )

    forwards = robot_push(RULES, space, scene, move.element, "FF", space.rects)
    assert forwards.travel > 0.0 and in_the_way(forwards)
    push = chosen_push(RULES, space, scene, move, rest, space.rects)
    assert push.direction in ("LL", "RR") and not in_the_way(push) and push.travel >= 0.01
    # Of the sideways pushes that clear the way, the one that moves the obstacle furthest.
    sideways = [robot_push(RULES, space, scene, move.element, d, space.rects) for d in ("LL", "RR")]
    assert push.travel == max(p.travel for p in sideways if not in_the_way(p) and p.travel >= 0.01)
    robot = robot_plan(human, scene, RULES)
    assert [(k.action, k.direction) for k in robot.keypoints if k.action in ("move", "release")] == [
        ("move", push.direction),
        ("release", push.direction),
    ]
    # Pushes already clear of the way keep the person's direction (gen1 seed 3: right, then left).
    scene = generate_scene("gen1", 3)
    human = plan(scene, default_models())
    robot = robot_plan(human, scene, RULES)
    assert (
        [k.direction for k in robot.keypoints if k.action == "move"]
        == [k.direction for k in human.keypoints if k.action == "move"]
        == ["RR", "LL"]
    )


def test_the_gripper_slides_onto_the_target_along_its_approach_axis():
    from hlp_drake.taskspace import Rect
    from hlp_drake.transfer.push import approach

    APPROACH_GAP, GRIPPER_AHEAD = RULES.approach_gap, RULES.gripper_ahead

    target = Rect(0.70, -0.03, 0.76, 0.03)
    # Coming in 35 degrees off +x: a waypoint APPROACH_GAP behind the target's back face, in line.
    (point,) = approach(RULES, (0.50, -0.14), target, {"t": target}, "t")
    assert point.action == "approach" and point.element == "t"
    assert point.position == pytest.approx((0.70 - APPROACH_GAP, 0.0))
    assert point.position[0] + GRIPPER_AHEAD < target.x_min  # the fingertips stop short of it
    # Already in line (within 15 degrees): none; an object where the gripper would be: none.
    assert approach(RULES, (0.40, 0.05), target, {"t": target}, "t") == []
    blocker = Rect(0.60, 0.04, 0.66, 0.10)
    assert approach(RULES, (0.50, -0.14), target, {"t": target, "b": blocker}, "t") == []
    # In a plan: gen1 seed 18 comes to the target from a gap 9 cm to its side.
    scene = generate_scene("gen1", 18)
    keypoints = robot_plan(plan(scene, default_models()), scene, RULES).keypoints
    before, last = keypoints[-2:]
    space = TaskSpace(scene)
    assert (before.action, last.action) == ("approach", "target")
    assert before.position == pytest.approx(
        (space.rects[scene.target.name].x_min - APPROACH_GAP, scene.target.y)
    )
