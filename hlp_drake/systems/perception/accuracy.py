"""How a perceived scene compares with the true one: objects matched, their errors, and whether the
human-like plan on it takes the same decisions row by row.

``perception_record(true_scene, perception)`` is the ``perception`` record of ``run_scene``'s JSON and
the benchmark's unit: per true object its perceived match (the targets with each other, the
obstacles by least total centre distance, ``object_matching.match_obstacles``, within
``MATCH_DISTANCE``), ``position_error_m`` (centres), ``size_error_m`` (the largest error of the
three extents), ``yaw_error_rad`` (boxes; a box's outline repeats every quarter turn with its sides
swapped, so the yaw is compared modulo pi/2 and the sizes in the matching order), the objects
missed and the objects invented.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np
from scipy.optimize import linear_sum_assignment

from hlp_drake.planner import HighLevelPlan
from hlp_drake.scene.model import Scene, SceneObject

if TYPE_CHECKING:
    from hlp_drake.systems.perception.system import Perception


MATCH_DISTANCE = 0.05
"""A perceived object further than this (m) from a true one's centre is not that object."""


def object_errors(true: SceneObject, seen: SceneObject) -> dict[str, Any]:
    """The errors of ``seen`` as a perception of ``true`` (see the module's docstring)."""
    position = math.hypot(seen.x - true.x, seen.y - true.y)
    sizes = np.array(seen.size[:2])
    yaw_error = None
    if true.shape == "box" and seen.shape == "box":
        turns = [math.remainder(seen.yaw + k * math.pi / 2 - true.yaw, math.pi) for k in (0, 1)]
        k = int(np.argmin(np.abs(turns)))
        yaw_error = abs(turns[k])
        sizes = sizes[::-1] if k else sizes
    extents = np.abs(np.append(sizes - np.array(true.size[:2]), seen.size[2] - true.size[2]))
    return {
        "name": true.name,
        "perceived_as": seen.name,
        "shape": true.shape,
        "perceived_shape": seen.shape,
        "position_error_m": position,
        "size_error_m": float(extents.max()),
        "size_errors_m": [float(e) for e in extents],
        "yaw_error_rad": yaw_error,
    }


def match_objects(true: Scene, seen: Scene) -> dict[str, str]:
    """Per true object's name, the name of the perceived object that is it (unmatched ones left out)."""
    matches = {}
    if math.hypot(seen.target.x - true.target.x, seen.target.y - true.target.y) <= MATCH_DISTANCE:
        matches[true.target.name] = seen.target.name
    rows, cols, distances = match_obstacles(
        np.array([o.position for o in true.obstacles]), np.array([o.position for o in seen.obstacles])
    )
    for i, j, distance in zip(rows, cols, distances):
        if distance <= MATCH_DISTANCE:
            matches[true.obstacles[i].name] = seen.obstacles[j].name
    return matches


def perception_record(true: Scene, perception: Perception) -> dict[str, Any]:
    """The ``perception`` record of a run: the frame's outcome (``Perception.to_dict``: the fitted
    objects under ``perceived``, each with the true object's name it was ``matched_to``, None if
    none), per true object its errors (``objects``), the objects ``missed``
    (true ones without a match) and ``invented`` (perceived ones without one), and the table's
    errors."""
    record = {**perception.to_dict(), "objects": [], "missed": [], "invented": []}
    seen = perception.scene
    if not perception.ok:
        record["missed"] = [o.name for o in true.objects]
        return record
    matches = match_objects(true, seen)
    by_name = {o.name: o for o in seen.objects}
    record["objects"] = [
        object_errors(o, by_name[matches[o.name]]) for o in true.objects if o.name in matches
    ]
    record["missed"] = [o.name for o in true.objects if o.name not in matches]
    matched = set(matches.values())
    record["invented"] = [o.name for o in seen.objects if o.name not in matched]
    true_of = {seen_name: true_name for true_name, seen_name in matches.items()}
    record["perceived"] = [
        {"name": o["name"], "matched_to": true_of.get(o["name"]), **o} for o in record["perceived"]
    ]
    table = true.table
    record["table_errors_m"] = {
        "length": seen.table.length - table.length,
        "width": seen.table.width - table.width,
        "height": seen.table.height - table.height,
    }
    return record


def plan_decisions(plan: HighLevelPlan, names: dict[str, str] | None = None) -> list[tuple]:
    """The plan's decision per row, in order: ("gap", index) or ("move", obstacle, direction), the
    obstacles renamed by ``names`` (a perceived name -> the true one)."""
    names = names or {}
    return [
        ("gap", k.element) if k.action == "gap" else ("move", names.get(k.element, k.element), k.direction)
        for k in plan.keypoints
        if k.action in ("gap", "move")
    ]


def same_decisions(
    true_plan: HighLevelPlan, seen_plan: HighLevelPlan, matches: dict[str, str]
) -> tuple[int, int]:
    """(rows decided alike, rows): the two plans' decisions compared row by row (a row only one
    plan has counts as decided differently)."""
    back = {seen: true for true, seen in matches.items()}
    a, b = plan_decisions(true_plan), plan_decisions(seen_plan, back)
    same = sum(x == y for x, y in zip(a, b))
    return same, max(len(a), len(b))


__all__ = [
    "MATCH_DISTANCE",
    "match_objects",
    "object_errors",
    "perception_record",
    "plan_decisions",
    "same_decisions",
]


# Which object of one scene is which of another, by position rather than by name.
#
# Perceived objects are named by their order on the table (``object_1``, ...), which the next frame
# may swap for two objects at almost the same x; comparing scenes by name would then see objects jump.
# ``match_obstacles`` pairs two sets of centres by least total distance (scipy's
# ``linear_sum_assignment``); the targets are each other.
def match_obstacles(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(indices into ``a``, indices into ``b``, their distances) of the pairing of the (n, 2+) and
    (m, 2+) centres ``a`` and ``b`` with least total horizontal distance (min(n, m) pairs)."""
    if len(a) == 0 or len(b) == 0:
        empty = np.zeros(0, int)
        return empty, empty, np.zeros(0)
    a, b = np.asarray(a, float), np.asarray(b, float)
    cost = np.linalg.norm(a[:, None, :2] - b[None, :, :2], axis=2)
    rows, cols = linear_sum_assignment(cost)
    return rows, cols, cost[rows, cols]


def largest_displacement(expected: np.ndarray, observed: np.ndarray) -> float:
    """How far the object that moved most has gone from ``expected`` (m, m >= 1 rows of x, y[, z],
    the target first) to ``observed`` (the same form), the obstacles paired by ``match_obstacles``;
    infinite if the obstacles' counts differ (an object appeared or went)."""
    expected, observed = np.asarray(expected, float), np.asarray(observed, float)
    if len(expected) != len(observed):
        return float("inf")
    target = float(np.hypot(*(observed[0, :2] - expected[0, :2])))
    _, _, distances = match_obstacles(expected[1:], observed[1:])
    return max([target, *distances.tolist()])
