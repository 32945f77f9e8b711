"""Steps 1-3 of the planner: classify gaps and obstacles, keep candidates per row, classify the
segments between consecutive rows and enumerate the paths along accepted segments.

Work is bounded per row: only the ``classify_per_row`` gaps and obstacles nearest the start-target
line are described and classified, and all rows share one classifier call per learner.
"""

from __future__ import annotations

from itertools import pairwise
from typing import TYPE_CHECKING

import numpy as np

from hlp_drake.features import gap_features, object_features
from hlp_drake.features.segment import node_pairs, pair_features
from hlp_drake.planner.config import PlannerConfig
from hlp_drake.taskspace import Node, TaskSpace

if TYPE_CHECKING:
    from hlp_drake.learners.models import DecisionModels


def line_offsets(centres: np.ndarray, start: np.ndarray, target: np.ndarray) -> np.ndarray:
    """Lateral distance of each (x, y) centre from the line from the start to the target, measured
    at the centre's depth."""
    x, y = centres[:, 0], centres[:, 1]
    t = (x - start[0]) / (target[0] - start[0]) if target[0] != start[0] else np.zeros(len(x))
    return np.abs(y - (start[1] + t * (target[1] - start[1])))


def nearest_per_row(
    rows: np.ndarray, centres: np.ndarray, start: np.ndarray, target: np.ndarray, limit: int
) -> np.ndarray:
    """Sorted indices of the items (row index, (x, y) centre) kept: per row the ``limit`` laterally
    nearest the line from the start to the target, measured at the item's depth (ties: the first)."""
    offset = line_offsets(centres, start, target)
    order = np.lexsort((offset, rows))  # by row, then offset; stable, so ties keep the item order
    first_of_row = np.searchsorted(rows[order], rows[order], side="left")
    return np.sort(order[np.arange(len(order)) - first_of_row < limit])


def classify(space: TaskSpace, models: DecisionModels, limit: int) -> tuple[np.ndarray, np.ndarray]:
    """Cg scores of the gaps (``space.gap_table`` order) and Co scores of the obstacles (scene
    order); -inf for those not classified (per row only the ``limit`` nearest the start-target line)."""
    start, target = np.asarray(space.scene.start, float), np.asarray(space.target.center, float)
    table, bounds = space.gap_table, space.obstacle_bounds
    gap_pick = nearest_per_row(table.row, table.centers, start, target, limit)
    object_pick = nearest_per_row(space.obstacle_rows, space.obstacle_centres, start, target, limit)
    gap_scores, object_scores = np.full(len(table.row), -np.inf), np.full(len(bounds), -np.inf)
    if len(gap_pick):
        gap_scores[gap_pick] = models.gap.decision_function(gap_features(space, gap_pick))
    if len(object_pick):
        object_scores[object_pick] = models.object.decision_function(object_features(space, object_pick))
    return gap_scores, object_scores


def informed(scores: np.ndarray, intercept: float, min_evidence: float) -> np.ndarray:
    """Which scores carry evidence: an RBF SVM scores a case far from every training example with
    its intercept alone (no kernel weight), which says nothing about that case."""
    return np.abs(np.asarray(scores) - intercept) >= min_evidence


def _accepted(scores: list[float], evidence: list[bool], offsets: list[float], cap: int) -> list[int]:
    """Positions kept: those scored > 0 (the best ``cap``), else the single best; if no score
    carries evidence, the one nearest the start-target line; in input order."""
    ranked = sorted(range(len(scores)), key=lambda k: -scores[k])
    positive = [k for k in ranked if scores[k] > 0 and evidence[k]][:cap]
    if positive or not scores:
        return sorted(positive)
    if not any(evidence):
        return [min(range(len(scores)), key=lambda k: offsets[k])]
    return ranked[:1]


def row_candidates(
    space: TaskSpace,
    models: DecisionModels,
    gap_scores: np.ndarray,
    object_scores: np.ndarray,
    config: PlannerConfig,
) -> list[list[Node]]:
    """Per row the accepted classified gaps (left to right; at least ``min_gap_width`` wide), then
    the accepted classified obstacles (scene order); of each kind the best one if none is accepted
    (the one nearest the start-target line if no score of the row carries evidence, ``informed``)."""
    table = space.gap_table
    start, target = np.asarray(space.scene.start, float), np.asarray(space.target.center, float)
    gap_offsets = line_offsets(table.centers, start, target)
    object_offsets = line_offsets(space.obstacle_centres, start, target)
    gap_evidence = informed(gap_scores, models.gap.intercept_, config.min_evidence)
    object_evidence = informed(object_scores, models.object.intercept_, config.min_evidence)
    gaps: list[list[int]] = [[] for _ in space.rows]
    objects: list[list[int]] = [[] for _ in space.rows]
    widths = table.bounds[:, 3] - table.bounds[:, 1]
    for k in np.flatnonzero(np.isfinite(gap_scores) & (widths >= config.min_gap_width)).tolist():
        gaps[table.row[k] - 1].append(k)
    for k in np.flatnonzero(np.isfinite(object_scores)).tolist():
        objects[space.obstacle_rows[k] - 1].append(k)
    centres, names = table.centers.tolist(), space.obstacle_names
    candidates = []
    for row, row_gaps, row_objects in zip(space.rows, gaps, objects):
        keep_gaps = [
            row_gaps[i]
            for i in _accepted(
                gap_scores[row_gaps].tolist(),
                gap_evidence[row_gaps].tolist(),
                gap_offsets[row_gaps].tolist(),
                config.max_gaps_per_row,
            )
        ]
        keep_objects = [
            row_objects[i]
            for i in _accepted(
                object_scores[row_objects].tolist(),
                object_evidence[row_objects].tolist(),
                object_offsets[row_objects].tolist(),
                config.max_objects_per_row,
            )
        ]
        candidates.append(
            [Node(row.index, "gap", tuple(centres[k]), gap=int(table.index[k])) for k in keep_gaps]
            + [
                Node(row.index, "object", space.rects[names[k]].center, obstacle=names[k])
                for k in keep_objects
            ]
        )
    return candidates


def segment_scores(
    space: TaskSpace, models: DecisionModels, candidates: list[list[Node]], config: PlannerConfig
) -> list[np.ndarray]:
    """Cc scores of every pair of candidates of consecutive rows: per row pair (near, far), all in
    one feature and one classifier call."""
    if len(candidates) < 2:
        return []
    pairs = [
        np.concatenate(part) for part in zip(*(node_pairs(space, a, b) for a, b in pairwise(candidates)))
    ]
    scores = models.segment.decision_function(pair_features(space, *pairs, mode=config.mode))
    sizes = [(len(a), len(b)) for a, b in pairwise(candidates)]
    split = np.cumsum([n * m for n, m in sizes])[:-1]
    return [block.reshape(shape) for block, shape in zip(np.split(scores, split), sizes)]


def enumerate_paths(
    sizes: list[int], scores: list[np.ndarray], max_paths: int, evidence: list[np.ndarray] | None = None
) -> list[tuple[tuple[int, ...], float]]:
    """Candidate positions (one per row) along accepted row-to-row segments and their summed
    score, best first (at most ``max_paths``).

    A pair is accepted when Cc scores it positive. As in the original, when no pair between two
    rows is accepted the two best pairs are; and a node with no accepted way on continues along
    its best-scoring segment, so there is always a path. Where ``evidence`` (per block, which
    scores carry evidence, ``informed``) says no score between two rows does, every pair is.
    """
    paths: list[tuple[tuple[int, ...], float]] = (
        [((i,), 0.0) for i in range(sizes[0])] if sizes else [((), 0.0)]
    )
    for b, block in enumerate(scores):
        ok = block > 0
        if evidence is not None and not evidence[b].any():
            ok = np.ones_like(ok)
        elif not ok.any():
            ok = np.zeros_like(ok)
            ok.flat[np.argsort(-block, axis=None)[:2]] = True
        following = [
            np.flatnonzero(row).tolist() or [int(np.argmax(values))] for row, values in zip(ok, block)
        ]
        values = block.tolist()
        extended = [
            (nodes + (j,), score + values[nodes[-1]][j])
            for nodes, score in paths
            for j in following[nodes[-1]]
        ]
        extended.sort(key=lambda p: -p[1])
        paths = extended[:max_paths]
    return paths
