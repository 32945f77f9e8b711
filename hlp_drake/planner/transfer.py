"""Transfer a human-like plan to a pushing robot (the paper's keypoints -> robot waypoints).

A person picks an obstacle up; the robot pushes it with the side of its gripper, which approaches
horizontally from the start's side. So a "move" keypoint (the obstacle's centre in the plan)
becomes the point just behind the obstacle's face opposite the push direction, and the "release"
keypoint the same point once the obstacle's centre has reached its new place. The robot cannot
pull an obstacle towards itself: backward directions (BB, BL, BR) become the sideways push of
their side (BL -> LL, BR -> RR, BB -> the freer of LL and RR).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from hlp_drake.planner.plan import HighLevelPlan, PlanKeypoint
from hlp_drake.planner.relocation import relocated
from hlp_drake.scene.model import Scene
from hlp_drake.taskspace import DIRECTION_VECTORS, TaskSpace

# Gap between the obstacle's face and the tcp at the push start: the fingertips reach ~1 cm ahead
# of the tcp, the open fingers' outer sides ~5.5 cm beside it; plus 2 cm of free approach.
FORWARD_CLEARANCE = 0.03
SIDEWAYS_CLEARANCE = 0.075
ROBOT_DIRECTIONS = {"BL": "LL", "BR": "RR"}
# A pushed obstacle stops this far short of the table's edge and of the other objects: a person
# lifts an obstacle over its neighbours, a pushing robot would shove them along (or off the table).
EDGE_MARGIN = 0.03
OBJECT_MARGIN = 0.01
TRAVEL_STEP = 0.005


def _robot_direction(space: TaskSpace, name: str, direction: str) -> str:
    if direction == "BB":
        free = dict(zip(("FF", "BB", "LL", "RR", "FR", "FL", "BR", "BL"), space.free_space(name)))
        return "LL" if free["LL"] >= free["RR"] else "RR"
    return ROBOT_DIRECTIONS.get(direction, direction)


def push_travel(space: TaskSpace, scene: Scene, name: str, unit: np.ndarray, wanted: float) -> float:
    """How far (<= ``wanted``) obstacle ``name`` can be pushed along ``unit`` before its footprint
    comes within ``EDGE_MARGIN`` of the table's edge or ``OBJECT_MARGIN`` of another object."""
    rect = space.rects[name]
    x_min, y_min, x_max, y_max = scene.table.bounds
    others = [r for other, r in space.rects.items() if other != name]
    steps = np.arange(TRAVEL_STEP, wanted + 1e-9, TRAVEL_STEP)
    travel = 0.0
    for t in steps:
        dx, dy = t * unit
        moved = (rect.x_min + dx, rect.y_min + dy, rect.x_max + dx, rect.y_max + dy)
        if (moved[0] < x_min + EDGE_MARGIN or moved[2] > x_max - EDGE_MARGIN
                or moved[1] < y_min + EDGE_MARGIN or moved[3] > y_max - EDGE_MARGIN):
            break
        if any(moved[0] < r.x_max + OBJECT_MARGIN and r.x_min - OBJECT_MARGIN < moved[2]
               and moved[1] < r.y_max + OBJECT_MARGIN and r.y_min - OBJECT_MARGIN < moved[3] for r in others):
            break
        travel = float(t)
    return travel


def robot_plan(plan: HighLevelPlan, scene: Scene) -> HighLevelPlan:
    """The plan with each move/release pair turned into the push's start and end points."""
    if not plan.ok:
        return plan
    space = TaskSpace(scene)
    keypoints: list[PlanKeypoint] = []
    for k in plan.keypoints:
        if k.action not in ("move", "release") or k.element not in space.rects:
            keypoints.append(k)
            continue
        rect = space.rects[k.element]
        direction = _robot_direction(space, k.element, k.direction)
        unit = np.array(DIRECTION_VECTORS[direction], float)
        unit /= np.linalg.norm(unit)
        # Distance from the centre to the face opposite the push, along the push direction.
        clearance = abs(unit[0]) * FORWARD_CLEARANCE + abs(unit[1]) * SIDEWAYS_CLEARANCE
        reach = abs(unit[0]) * rect.depth / 2.0 + abs(unit[1]) * rect.width / 2.0 + clearance
        centre = np.array(rect.center)
        if k.action == "release":  # towards the relocated place, short of the edge and the others
            wanted = float(np.dot(np.subtract(relocated(rect, direction, space.alpha).center, centre), unit))
            centre = centre + push_travel(space, scene, k.element, unit, max(wanted, 0.0)) * unit
        point = centre - reach * unit
        keypoints.append(replace(k, position=(float(point[0]), float(point[1])), direction=direction))
    return replace(plan, keypoints=tuple(keypoints))
