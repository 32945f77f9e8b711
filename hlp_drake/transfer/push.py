"""Transfer a human-like plan to a pushing robot (the paper's keypoints -> robot waypoints).

A person picks an obstacle up; the robot pushes it with the side of its gripper, which approaches
horizontally from the start's side. So a "move" keypoint (the obstacle's centre in the plan)
becomes the point just behind the obstacle's face opposite the push direction, and the "release"
keypoint the same point once the obstacle's centre has reached its new place. The robot cannot
pull an obstacle towards itself: a backward direction (BB, BL, BR) becomes the sideways push (LL or
RR) that leaves the least of the obstacle in the corridor along the straight start-target line (a
person lifts the obstacle back over the table; pushed sideways into the corridor it would block the
way), the side the obstacle lies on when both leave the same. A push that cannot move the obstacle
``min_push_travel`` before it nears the table's edge or another object is left out: pressing it
into its neighbours would only shove them along (or off the table).
A person can put an obstacle down anywhere; a push that would leave it in the way on through the
gaps to the target goes another way (``chosen_push``).

A person lifts their hand over the table on the way to an obstacle; a robot arm moving sideways at
push height would sweep its forearm through everything between the base and the gripper. So the
way to each push start, and any other way whose tcp path would pass over an object (within
``path_clearance`` of its footprint, the objects where the pushes so far left them), goes over the
objects: two "transit" waypoints ``transit_clearance`` over the tallest object, above the previous
waypoint and above the next one, where the arm comes down, if nothing lies under the arm there
(else the waypoint is reached directly, at push height). The gripper's approach axis is +x; coming
onto the target from the side would sweep it along, so the way ends with an "approach" waypoint
``approach_gap`` behind the target, from where the gripper slides straight on.

The clearances (``PushRules``, in backticks here) are ``TransferConfig``'s margins on the robot's
sizes, which ``hlp_drake.transfer.rules`` reads from the robot model. The ``RobotPlanTransfer``
block (``hlp_drake.systems.planning.transfer``) runs this in a diagram.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from itertools import pairwise

import numpy as np

from hlp_drake.planner.plan import HighLevelPlan, PlanKeypoint
from hlp_drake.scene.model import Scene
from hlp_drake.taskspace import DIRECTION_VECTORS, Rect, TaskSpace, rect_array
from hlp_drake.taskspace.relocation import relocated
from hlp_drake.transfer.rules import PushRules

ROBOT_ACTIONS = ("start", "gap", "move", "release", "target", "transit", "approach")
"""The actions of a robot plan: the person's (``hlp_drake.planner.ACTIONS``), "transit" (a waypoint
lifted clear of the objects) and "approach" (the waypoint the gripper slides onto the target from)."""
BACKWARD = ("BB", "BL", "BR")
TRANSFERRED = "robot_plan"
"""The key ``robot_plan`` sets in a plan's ``details``: its moves are the robot's pushes (``KeypointIk``
refuses a person's moves, the obstacles' centres)."""


def _robot_direction(
    rules: PushRules,
    space: TaskSpace,
    scene: Scene,
    name: str,
    direction: str,
    footprints: Mapping[str, Rect] | None = None,
) -> str:
    """The robot's push direction for a person's move of obstacle ``name`` towards ``direction``
    (the other objects at ``footprints``, by default where the scene has them)."""
    if direction not in BACKWARD:
        return direction
    start = np.asarray(scene.start, float)
    line = np.array([scene.target.x, scene.target.y]) - start
    normal = np.array([-line[1], line[0]]) / np.linalg.norm(line)
    rect = space.rects[name]
    corners = np.array([[x, y] for x in (rect.x_min, rect.x_max) for y in (rect.y_min, rect.y_max)])
    away = "LL" if float(np.dot(np.array(rect.center) - start, normal)) >= 0 else "RR"

    def blocking(side: str) -> float:  # how much of the corridor the obstacle still covers after the push
        unit = _unit(side)
        travel = robot_push(
            rules, space, scene, name, side, space.rects if footprints is None else footprints
        ).travel
        lateral = (corners + travel * unit - start) @ normal
        half = rules.corridor_half_width
        return max(0.0, min(lateral.max(), half) - max(lateral.min(), -half))

    return min((away, "RR" if away == "LL" else "LL"), key=blocking)


def _unit(direction: str) -> np.ndarray:
    unit = np.array(DIRECTION_VECTORS[direction], float)
    return unit / np.linalg.norm(unit)


def _wanted(space: TaskSpace, name: str, direction: str) -> float:
    """How far obstacle ``name``'s centre moves along ``direction`` to its relocated place."""
    rect = space.rects[name]
    shift = np.subtract(relocated(rect, direction, space.alpha).center, rect.center)
    return max(float(np.dot(shift, _unit(direction))), 0.0)


def push_travel(
    rules: PushRules,
    space: TaskSpace,
    scene: Scene,
    name: str,
    unit: np.ndarray,
    wanted: float,
    footprints: Mapping[str, Rect] | None = None,
    tcp: tuple[float, float] | None = None,
) -> float:
    """How far (<= ``wanted``, in ``rules.travel_step`` steps) obstacle ``name`` can be pushed along
    ``unit`` before its footprint comes within ``rules.edge_margin`` of the table's edge or
    ``rules.object_margin`` of another object, or (from ``tcp``, the push's start) the pushing hand
    (``rules.hand``) sweeps that close to another object, the objects' footprints being ``footprints``
    (by default where the scene has them). An edge or object already nearer than that only stops a
    push that brings the obstacle or the hand closer to it."""
    footprints = space.rects if footprints is None else footprints
    rect = space.rects[name]
    steps = np.arange(rules.travel_step, wanted + 1e-9, rules.travel_step)
    if steps.size == 0:
        return 0.0
    start = rect_array([rect])[0]
    boxes = np.vstack([start, start + np.outer(steps, [unit[0], unit[1], unit[0], unit[1]])])
    x_min, y_min, x_max, y_max = scene.table.bounds
    edges = np.column_stack(
        [boxes[:, 0] - x_min, boxes[:, 1] - y_min, x_max - boxes[:, 2], y_max - boxes[:, 3]]
    )
    blocked = _nearing(edges, rules.edge_margin)
    others = rect_array([r for other, r in footprints.items() if other != name])
    if others.size:
        blocked |= _nearing(_gaps(boxes, others), rules.object_margin)
        shifts = np.vstack([np.zeros(2), np.outer(steps, unit)])
        for part in rules.hand if tcp is not None else ():  # the hand, swept along from the push's start
            hand = np.add(part, [tcp[0], tcp[1], tcp[0], tcp[1]]) + np.hstack([shifts, shifts])
            blocked |= _nearing(_gaps(hand, others), rules.object_margin)
    stops = np.flatnonzero(blocked[1:])  # blocked[i + 1]: after steps[i]
    if stops.size == 0:
        return float(steps[-1])
    return float(steps[stops[0] - 1]) if stops[0] > 0 else 0.0


def _gaps(boxes: np.ndarray, others: np.ndarray) -> np.ndarray:
    """(len(boxes), len(others)): the gap between each box and each other box along the axis that
    separates them most (negative: they overlap)."""
    return np.max(
        [
            others[None, :, 0] - boxes[:, None, 2],
            boxes[:, None, 0] - others[None, :, 2],
            others[None, :, 1] - boxes[:, None, 3],
            boxes[:, None, 1] - others[None, :, 3],
        ],
        axis=0,
    )


def _nearing(distances: np.ndarray, margin: float) -> np.ndarray:
    """Per row (row 0: the start) whether any distance is below ``margin`` and below its start."""
    return ((distances < margin) & (distances < distances[0] - 1e-12)).any(axis=1)


@dataclass(frozen=True)
class RobotPush:
    """One push of the robot plan: its direction, how far it moves the obstacle, the tcp's start
    and end points and the obstacle's footprint after it."""

    direction: str
    travel: float
    start: tuple[float, float]
    end: tuple[float, float]
    footprint: Rect


def robot_push(
    rules: PushRules, space: TaskSpace, scene: Scene, name: str, direction: str, placed: Mapping[str, Rect]
) -> RobotPush:
    """The push of obstacle ``name`` towards ``direction``: towards its relocated place, short of
    the edge and the other objects (at ``placed``) and of sweeping the hand into them, from just
    behind its face opposite the push (the closed fingers', or beside a deep obstacle the palm's,
    ``sideways_margin`` short of it)."""
    rect = space.rects[name]
    unit = _unit(direction)
    # Distance from the centre to the face opposite the push, along the push direction.
    palm_beside = rect.depth / 2.0 > rules.palm_front  # the palm reaches the obstacle's depth
    sideways = rules.palm_sideways_clearance if palm_beside else rules.sideways_clearance
    clearance = abs(unit[0]) * rules.forward_clearance + abs(unit[1]) * sideways
    reach = abs(unit[0]) * rect.depth / 2.0 + abs(unit[1]) * rect.width / 2.0 + clearance
    start = np.array(rect.center) - reach * unit
    wanted = _wanted(space, name, direction)
    travel = push_travel(rules, space, scene, name, unit, wanted, footprints=placed, tcp=(start[0], start[1]))
    dx, dy = travel * unit
    return RobotPush(
        direction,
        travel,
        (float(start[0]), float(start[1])),
        (float(start[0] + dx), float(start[1] + dy)),
        Rect(rect.x_min + dx, rect.y_min + dy, rect.x_max + dx, rect.y_max + dy),
    )


def chosen_push(
    rules: PushRules,
    space: TaskSpace,
    scene: Scene,
    move: PlanKeypoint,
    rest: Sequence[PlanKeypoint],
    placed: Mapping[str, Rect],
) -> RobotPush:
    """The robot's push for the person's ``move``: towards the person's direction (a backward move
    made sideways), unless that leaves the obstacle within ``rules.way_clearance`` of the way on through
    the gaps to the target (``rest``: the plan's later keypoints); then the push among LL, RR and
    FF that leaves the way clear and moves the obstacle furthest, if any does."""
    direction = _robot_direction(rules, space, scene, move.element, move.direction, footprints=placed)
    first = robot_push(rules, space, scene, move.element, direction, placed)
    ways = [k.position for k in rest if k.action in ("gap", "target")]

    def clear(push: RobotPush) -> bool:
        points = [push.end, *ways]
        return push.travel >= rules.min_push_travel and not any(
            crosses(rules, a, b, [push.footprint], clearance=rules.way_clearance) for a, b in pairwise(points)
        )

    if not ways or clear(first):
        return first
    others = [
        robot_push(rules, space, scene, move.element, d, placed)
        for d in ("LL", "RR", "FF")
        if d != first.direction
    ]
    return max((push for push in others if clear(push)), key=lambda push: push.travel, default=first)


def robot_plan(plan: HighLevelPlan, scene: Scene, rules: PushRules) -> HighLevelPlan:
    """The plan with each move/release pair turned into the push's start and end points (see
    ``chosen_push``), pushes with no room left out, and the ways that would pass over objects
    going over them where the arm can come down (see ``transit``)."""
    if not plan.ok:
        return plan
    space = TaskSpace(scene)
    placed = dict(space.rects)  # the objects' footprints as the pushes so far leave them
    keypoints: list[PlanKeypoint] = []
    pushes: dict[str, RobotPush] = {}
    for i, k in enumerate(plan.keypoints):
        if k.action not in ("move", "release") or k.element not in space.rects:
            if k.action == "target" and keypoints:
                for point in approach(
                    rules, keypoints[-1].position, placed[scene.target.name], placed, scene.target.name
                ):
                    keypoints += _way_to(rules, keypoints, point, scene, placed)
                    keypoints.append(point)
            keypoints += _way_to(rules, keypoints, k, scene, placed)
            keypoints.append(k)
            continue
        if k.action == "move" or k.element not in pushes:
            pushes[k.element] = chosen_push(rules, space, scene, k, plan.keypoints[i + 1 :], placed)
        push = pushes[k.element]
        if push.travel < rules.min_push_travel:
            continue
        if k.action == "move":
            start = replace(k, position=push.start, direction=push.direction)
            keypoints += _way_to(rules, keypoints, start, scene, placed)
            keypoints.append(start)
        else:
            placed[k.element] = push.footprint
            keypoints.append(replace(k, position=push.end, direction=push.direction))
    return replace(plan, keypoints=tuple(keypoints), details={**plan.details, TRANSFERRED: True})


def robot_alternatives(
    plan: HighLevelPlan, scene: Scene, rules: PushRules, limit: int
) -> tuple[HighLevelPlan, ...]:
    """The robot plans (``robot_plan``) of ``plan``'s alternative candidates, best first: at most
    ``limit``, each different from the chosen plan's and from the earlier ones (two candidates
    can differ only where the transfer makes them the same, e.g. in a push it leaves out)."""
    if not plan.ok or limit <= 0:
        return ()
    seen = {robot_plan(plan, scene, rules).keypoints}
    found: list[HighLevelPlan] = []
    for candidate in plan.alternatives:
        robot = robot_plan(
            replace(
                plan,
                keypoints=candidate.keypoints,
                expected_collision=candidate.expected_collision,
                alternatives=(),
            ),
            scene,
            rules,
        )
        if robot.ok and robot.keypoints not in seen:
            seen.add(robot.keypoints)
            found.append(robot)
            if len(found) == limit:
                break
    return tuple(found)


def approach(
    rules: PushRules, previous: tuple[float, float], target: Rect, placed: Mapping[str, Rect], name: str
) -> list[PlanKeypoint]:
    """The waypoint ``approach_gap`` behind the ``target`` footprint from which the gripper slides
    straight onto it, if the way from ``previous`` would come in more than ``rules.approach_angle`` off
    the approach axis and the gripper fits there, clear of the other objects (``placed``, the
    target ``name`` aside); else none."""
    x, y = target.x_min - rules.approach_gap, (target.y_min + target.y_max) / 2.0
    dx, dy = target.center[0] - previous[0], target.center[1] - previous[1]
    if dx > 0.0 and abs(np.arctan2(dy, dx)) <= rules.approach_angle:
        return []
    half = rules.gripper_half_width
    gripper = Rect(x - rules.gripper_behind, y - half, x + rules.gripper_ahead, y + half)
    if any(gripper.overlap(r) > 0.0 for other, r in placed.items() if other != name):
        return []
    return [PlanKeypoint("approach", (float(x), float(y)), element=name)]


def _way_to(
    rules: PushRules, keypoints: list[PlanKeypoint], k: PlanKeypoint, scene: Scene, placed: Mapping[str, Rect]
) -> list[PlanKeypoint]:
    """The transit waypoints on the way from the last of ``keypoints`` to ``k``, a push start or a
    waypoint the hand passes: over the objects to a push start, or where the straight way would
    pass over an object (the target aside), if the arm can come down at ``k`` (the target aside
    when ``k`` is the target)."""
    if not keypoints:
        return []
    target = scene.target.name
    others = [r for name, r in placed.items() if name != target]
    if k.action != "move" and not crosses(rules, keypoints[-1].position, k.position, others):
        return []
    under = others if k.action == "target" else list(placed.values())
    return transit(rules, keypoints[-1], k, transit_height(rules, scene), under)


def crosses(
    rules: PushRules, a: tuple[float, float], b: tuple[float, float], rects, *, clearance: float | None = None
) -> bool:
    """Whether the straight tcp path from ``a`` to ``b`` passes within ``clearance`` (default
    ``rules.path_clearance``) of any of ``rects`` (sampled every ``rules.travel_step``)."""
    clearance = rules.path_clearance if clearance is None else clearance
    boxes = rect_array(list(rects))
    if boxes.size == 0:
        return False
    count = max(int(np.ceil(np.hypot(b[0] - a[0], b[1] - a[1]) / rules.travel_step)), 1) + 1
    points = np.linspace(a, b, count)[:, None, :]
    inside = (
        (points[..., 0] > boxes[:, 0] - clearance)
        & (points[..., 0] < boxes[:, 2] + clearance)
        & (points[..., 1] > boxes[:, 1] - clearance)
        & (points[..., 1] < boxes[:, 3] + clearance)
    )
    return bool(inside.any())


def transit_height(rules: PushRules, scene: Scene) -> float:
    """The tcp's height above the table top on transit waypoints."""
    return max(obj.size[2] for obj in scene.objects) + rules.transit_clearance


def arm_shadow(rules: PushRules, x: float, y: float) -> Rect:
    """The table area under the gripper and wrist when the tcp is at (x, y) at push height."""
    half = rules.arm_shadow_half_width
    return Rect(x - rules.arm_shadow_length, y - half, x, y + half)


def transit(
    rules: PushRules, previous: PlanKeypoint, push: PlanKeypoint, height: float, objects
) -> list[PlanKeypoint]:
    """The waypoints over the objects from ``previous`` to the push start ``push``: lifted above
    ``previous`` and above the push start, from where the arm comes straight down. None if an
    object lies under the arm at the push start (``arm_shadow``): the push start is then reached
    directly, at push height."""
    if any(arm_shadow(rules, *push.position).overlap(o) > 0.0 for o in objects):
        return []
    return [
        PlanKeypoint("transit", point, push.row, push.element, height=height)
        for point in (previous.position, push.position)
    ]
