"""Two trivial planners to score beside the learned one: a one-line geometric rule and a majority class.

- ``nearest_gap_plan``: every row is passed through its free interval (gap) nearest the straight
  line from the start to the target, measured at the row's depth.
- ``majority_plan``: every row gets the decision most common in the training rows ("gap" or
  "object"), with the row's first element of that kind from the left (gap 1, or the leftmost
  obstacle).

Neither has classifier labels: its raw labels (``details``) accept exactly the element it uses.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Iterable

import numpy as np

from hlp_drake.features.row_geometry import line_at
from hlp_drake.planner.plan import HighLevelPlan, PlanKeypoint
from hlp_drake.scene.model import Scene
from hlp_drake.segmentation.demonstration import GAP, NONE, OBJECT, Demonstration
from hlp_drake.taskspace import TaskSpace

BASELINES = ("nearest_gap", "majority")


def choice_plan(
    scene: Scene, space: TaskSpace, choices: list[tuple[int, str, str, tuple[float, float]]]
) -> HighLevelPlan:
    """A plan through ``choices`` (row, "gap"/"object", element, position) with one-hot raw labels
    (a row without a choice gets none)."""
    keypoints = [PlanKeypoint("start", (float(scene.start[0]), float(scene.start[1])))]
    gap_scores = {f"{g.row}:{g.index}": -0.5 for gaps in space.gaps for g in gaps}
    object_scores = dict.fromkeys(space.obstacle_names, -0.5)
    for row, kind, element, position in choices:
        if kind == GAP:
            keypoints.append(PlanKeypoint("gap", position, row, element))
            gap_scores[f"{row}:{element}"] = 0.5
        else:
            keypoints += [
                PlanKeypoint("move", position, row, element),
                PlanKeypoint("release", position, row, element),
            ]
            object_scores[element] = 0.5
    keypoints.append(PlanKeypoint("target", space.target.center, None, scene.target.name))
    return HighLevelPlan(
        scene.name, tuple(keypoints), details={"gap_scores": gap_scores, "object_scores": object_scores}
    )


def nearest_gap_plan(scene: Scene) -> HighLevelPlan:
    """Every row through its free interval nearest the start-target line."""
    space = TaskSpace(scene)
    start, goal = np.asarray(scene.start, float), np.asarray(space.target.center, float)
    choices = []
    for row, gaps in zip(space.rows, space.gaps):
        if not gaps:
            continue
        line = float(line_at(start, goal, row.x))
        bounds = np.array([(g.rect.y_min, g.rect.y_max) for g in gaps])
        offset = np.maximum(np.maximum(bounds[:, 0] - line, line - bounds[:, 1]), 0.0)
        gap = gaps[int(np.argmin(offset))]
        choices.append((row.index, GAP, str(gap.index), gap.center))
    return choice_plan(scene, space, choices)


def majority_decision(demonstrations: Iterable[Demonstration]) -> str:
    """The most common decision ("gap" or "object") of the rows the people crossed."""
    counts = Counter(d.decision for demo in demonstrations for d in demo.decisions if d.decision != NONE)
    return OBJECT if counts[OBJECT] > counts[GAP] else GAP


def majority_plan(scene: Scene, decision: str) -> HighLevelPlan:
    """Every row gets ``decision``, with the row's leftmost element of that kind."""
    space = TaskSpace(scene)
    choices = []
    for row, gaps in zip(space.rows, space.gaps):
        if decision == OBJECT and row.members:
            name = row.members[0]
            choices.append((row.index, OBJECT, name, space.rects[name].center))
        elif gaps:
            choices.append((row.index, GAP, str(gaps[0].index), gaps[0].center))
    return choice_plan(scene, space, choices)
