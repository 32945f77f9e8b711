"""The human-like planner: Algorithm 1 of the paper over the task space of any scene (reference 6)."""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from hlp_drake.features import (
    arm_features,
    direction_features,
    gap_features,
    object_features,
    segment_feature_matrix,
    table_diagonal,
)
from hlp_drake.learners.models import DecisionModels
from hlp_drake.planner.config import PlannerConfig
from hlp_drake.planner.human_arm import arm_joints, sweep_collision
from hlp_drake.planner.plan import HighLevelPlan, PlanCandidate, PlanKeypoint
from hlp_drake.planner.relocation import relocated
from hlp_drake.scene.model import Scene
from hlp_drake.scene.validation import scene_problems
from hlp_drake.segmentation.modes import is_faithful
from hlp_drake.taskspace import DIRECTIONS, Node, TaskSpace, direction_of
from hlp_drake.features.segment import PATH_WALLS, path_occluders
from hlp_drake.scene.generators import VR_TABLE


@dataclass
class _Path:
    nodes: tuple[Node, ...]
    score: float
    keypoints: list[PlanKeypoint] = field(default_factory=list)
    arms: list[np.ndarray] = field(default_factory=list)
    cost: float = 0.0


def _row_candidates(nodes: list[Node], score: dict[Node, float], kind: str, cap: int, min_width: float,
                    space: TaskSpace) -> list[Node]:
    """Accepted candidates of one kind (score > 0, best ``cap``), else the single best one; in the
    row's order (gaps left to right, obstacles in scene order)."""
    pool = [n for n in nodes if n.kind == kind
            and (kind == "object" or space.gaps[n.row - 1][n.gap - 1].width >= min_width)]
    ranked = sorted(pool, key=lambda n: -score[n])
    accepted = [n for n in ranked if score[n] > 0][:cap] or ranked[:1]
    return [n for n in pool if n in accepted]


def _enumerate_paths(candidates: list[list[Node]], segment_scores: list[np.ndarray], max_paths: int) -> list[_Path]:
    """Node sequences (one per row) along accepted row-to-row segments, best summed score first.

    A pair is accepted when Cc scores it positive. As in the original, when no pair between two
    rows is accepted the two best pairs are; and a node with no accepted way on continues along
    its best-scoring segment, so there is always a path.
    """
    accepted = []
    for scores in segment_scores:
        ok = scores > 0
        if not ok.any():
            best = np.argsort(-scores, axis=None)[:2]
            ok = np.zeros_like(ok)
            ok.flat[best] = True
        accepted.append(ok)
    paths = [_Path((n,), 0.0) for n in candidates[0]]
    for r, ok in enumerate(accepted):
        extended = []
        for path in paths:
            i = candidates[r].index(path.nodes[-1])
            following = np.flatnonzero(ok[i]) if ok[i].any() else [int(np.argmax(segment_scores[r][i]))]
            for j in following:
                extended.append(_Path(path.nodes + (candidates[r + 1][j],), path.score + float(segment_scores[r][i, j])))
        extended.sort(key=lambda p: -p.score)
        paths = extended[:max_paths]
    return paths


def _nearest_per_row(space: TaskSpace, items: list[tuple[int, tuple[float, float]]], start: np.ndarray,
                     target: np.ndarray, limit: int) -> np.ndarray:
    """Indices of ``items`` (row, centre) kept: per row the ``limit`` laterally nearest the line
    from the start to the target (measured at the item's depth)."""
    keep = []
    for row in space.rows:
        index = [i for i, (r, _) in enumerate(items) if r == row.index]
        if len(index) > limit:
            def offset(i: int) -> float:
                x, y = items[i][1]
                t = (x - start[0]) / (target[0] - start[0]) if target[0] != start[0] else 0.0
                return abs(y - (start[1] + t * (target[1] - start[1])))
            index = sorted(sorted(index, key=offset)[:limit])
        keep += index
    return np.array(sorted(keep), dtype=int)


def _no_plan(scene: Scene, reason: str, started: float) -> HighLevelPlan:
    return HighLevelPlan(scene.name, (), reason=reason, planning_time_s=time.perf_counter() - started)


def plan(scene: Scene, models: DecisionModels, config: PlannerConfig | None = None, *,
         start_arm: tuple[float, float] | None = None,
         link_lengths: tuple[float, float] | None = None) -> HighLevelPlan:
    """Plan how a person would reach the target of ``scene``.

    Args:
        scene: the scene (any number of rows).
        models: fitted decision models (trained in ``config.mode``).
        config: planner settings.
        start_arm: the arm's (q1, q2) at the start (default: the demonstrators' median).
        link_lengths: (upper arm, forearm) (default: the demonstrators' median scaled to the table).

    Returns:
        The plan, or a plan with ``reason`` set (never an exception for a bad scene).
    """
    started = time.perf_counter()
    config = config or PlannerConfig(mode=models.mode)
    if config.mode != models.mode:
        return _no_plan(scene, f"models were trained in {models.mode} mode, the planner runs in {config.mode}", started)
    problems = scene_problems(scene)
    if problems:
        return _no_plan(scene, "invalid scene: " + "; ".join(problems), started)
    faithful = is_faithful(config.mode)
    space = TaskSpace(scene)
    scale = table_diagonal(scene.table) / table_diagonal(VR_TABLE)  # arm lengths scale with the table
    upper, fore = link_lengths if link_lengths is not None else tuple(np.asarray(models.link_lengths_) * scale)
    arm_total = upper + fore
    q0 = np.asarray(start_arm if start_arm is not None else models.start_arm_, float)
    start = np.asarray(scene.start, float)
    target = np.asarray(space.target.center, float)

    # 1. Classify the gaps and obstacles once (per row the ones nearest the start-target line).
    gaps = [g for row in space.gaps for g in row]
    names = space.obstacle_names
    gap_pick = _nearest_per_row(space, [(g.row, g.center) for g in gaps], start, target, config.classify_per_row)
    row_of = {n: row.index for row in space.rows for n in row.members}
    object_pick = _nearest_per_row(space, [(row_of[n], space.rects[n].center) for n in names], start, target,
                                   config.classify_per_row)
    gap_scores = np.full(len(gaps), -np.inf)
    object_scores = np.full(len(names), -np.inf)
    if len(gap_pick):
        gap_scores[gap_pick] = models.gap.decision_function(gap_features(space)[gap_pick])
    if len(object_pick):
        object_scores[object_pick] = models.object.decision_function(object_features(space)[object_pick])
    details = {
        "gap_scores": {f"{g.row}:{g.index}": float(s) for g, s in zip(gaps, gap_scores) if np.isfinite(s)},
        "object_scores": {n: float(s) for n, s in zip(names, object_scores) if np.isfinite(s)},
    }

    # 2. Candidates per row (only classified gaps and obstacles).
    gap_score = {(g.row, g.index): s for g, s in zip(gaps, gap_scores)}
    object_score = dict(zip(names, object_scores))
    candidates: list[list[Node]] = []
    for row in space.rows:
        score = {n: gap_score[(n.row, n.gap)] if n.kind == "gap" else object_score[n.obstacle]
                 for n in space.nodes(row.index)}
        nodes = [n for n, s in score.items() if np.isfinite(s)]
        candidates.append(
            _row_candidates(nodes, score, "gap", config.max_gaps_per_row, config.min_gap_width, space)
            + _row_candidates(nodes, score, "object", config.max_objects_per_row, config.min_gap_width, space))

    # 3. Segments between consecutive rows, classified; paths along accepted segments.
    segment_scores = []
    for r in range(len(candidates) - 1):
        X = segment_feature_matrix(space, candidates[r], candidates[r + 1], mode=config.mode)
        segment_scores.append(models.segment.decision_function(X).reshape(len(candidates[r]), len(candidates[r + 1])))
    paths = _enumerate_paths(candidates, segment_scores, config.max_paths) if candidates else [_Path((), 0.0)]

    # 4. Keypoints per path; moved obstacles' directions by Cd (batched per row).
    for path in paths:
        path.keypoints.append(PlanKeypoint("start", (float(start[0]), float(start[1]))))
    for r in range(len(candidates)):
        queries = [(p, p.nodes[r]) for p in paths if p.nodes[r].kind == "object"]
        if queries:
            X = np.array([direction_features(space, n.obstacle, hand=p.keypoints[-1].position, mode=config.mode)
                          for p, n in queries])
            labels = models.direction.predict(X)
        for path in paths:
            node = path.nodes[r]
            if node.kind == "gap":
                path.keypoints.append(PlanKeypoint("gap", node.center, node.row, node.element))
        for (path, node), label in zip(queries, labels if queries else []):
            direction = DIRECTIONS[int(label)]
            release = relocated(space.rects[node.obstacle], direction, space.alpha).center
            path.keypoints += [PlanKeypoint("move", node.center, node.row, node.obstacle, direction),
                               PlanKeypoint("release", release, node.row, node.obstacle, direction)]
    for path in paths:
        path.keypoints.append(PlanKeypoint("target", (float(target[0]), float(target[1])), None, scene.target.name))

    # 5. Arm configurations by Ra, step by step across all paths, and the arm's expected collision.
    for path in paths:
        path.arms.append(q0)
    longest = max(len(p.keypoints) for p in paths)
    for k in range(1, longest):
        active = [p for p in paths if len(p.keypoints) > k]
        X = []
        for p in active:
            step = np.subtract(p.keypoints[k].position, p.keypoints[k - 1].position)
            X.append(arm_features(p.arms[-1], step / arm_total, direction_of(*step, faithful=faithful)))
        predicted = models.arm.predict(np.array(X))
        for p, q in zip(active, predicted):
            p.arms.append(np.clip(q, 0.0, np.pi))
    occluders = path_occluders(space, faithful=faithful)
    before, after, masks, owner = [], [], [], []
    for index, path in enumerate(paths):
        gone: set[str] = set()
        hands = np.array([k.position for k in path.keypoints])
        joints = arm_joints(hands, np.array(path.arms), upper, fore)
        for k in range(1, len(path.keypoints)):
            for keypoint in (path.keypoints[k - 1], path.keypoints[k]):
                if keypoint.action == "move":
                    gone.add(keypoint.element)
            before.append(joints[k - 1])
            after.append(joints[k])
            masks.append([n not in gone for n in names] + [True] * len(PATH_WALLS))
            owner.append(index)
    if len(paths) > 1 or not faithful:
        costs = sweep_collision(np.array(before), np.array(after), occluders, np.array(masks, dtype=bool),
                                band=config.arm_band, faithful=faithful)
        for index, cost in zip(owner, costs):
            paths[index].cost += float(cost)

    # 6. The path with the least expected collision (ties: the first).
    best = min(range(len(paths)), key=lambda i: paths[i].cost)
    chosen = paths[best]
    keypoints = tuple(
        PlanKeypoint(k.action, (float(k.position[0]), float(k.position[1])), k.row, k.element, k.direction,
                     (float(q[0]), float(q[1])))
        for k, q in zip(chosen.keypoints, chosen.arms)
    )
    alternatives = tuple(sorted((PlanCandidate(tuple(p.keypoints), p.cost) for i, p in enumerate(paths) if i != best),
                                key=lambda c: c.expected_collision))
    details["candidates"] = {str(r + 1): [n.element for n in c] for r, c in enumerate(candidates)}
    return HighLevelPlan(scene.name, keypoints, chosen.cost, alternatives, time.perf_counter() - started, None, details)
