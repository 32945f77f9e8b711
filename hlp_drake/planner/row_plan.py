"""The row-by-row planner: the paper's Algorithm 1 for any layout and any number of rows.

The paper plans two rows at once and names the way to more (Section VIII): rows handled
recursively, each from a sub-start towards the target. Here the rows between the start and the
target are planned in order. At each row the row-choice classifier Cr scores the row's gaps and
obstacles as the hand sees them from its keypoint at the row before (its sub-start), on its way to
the target, with the rows still ahead in view through the free-space route features. A beam keeps
the most likely partial plans (the product of each row's normalised choice probabilities). A moved
obstacle's direction comes from Cd and its release point is where the hand goes on from; the arm
configurations (Ra) and the arm's expected collision are computed for every plan of the beam, as
in Algorithm 1, and break ties.

A row none of whose candidates lies within the demonstrations' range (``RowChoiceClassifier``'s
novelty) keeps the one-line rule instead: the gap nearest the hand's line to the target.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from itertools import pairwise
from typing import TYPE_CHECKING

import numpy as np

from hlp_drake.features import DIRECTION_FEATURES, direction_index
from hlp_drake.features.direction import DirectionTable
from hlp_drake.features.row_choice import RowCandidates, RowChoiceScene
from hlp_drake.planner.config import PlannerConfig
from hlp_drake.planner.plan import HighLevelPlan, PlanCandidate, PlanKeypoint
from hlp_drake.planner.rollout import PrefixTree, arm_configurations, expected_collisions
from hlp_drake.scene.rows import Row
from hlp_drake.taskspace import DIRECTIONS, TaskSpace
from hlp_drake.taskspace.routes import segment_inside

if TYPE_CHECKING:
    from hlp_drake.learners.models import DecisionModels

REACH_FRACTION = 0.25  # the hand stops this many hand widths short of the target's near face


@dataclass(frozen=True)
class _Partial:
    """A plan up to some row."""

    keypoints: tuple[PlanKeypoint, ...]
    hand: tuple[float, float]
    removed: frozenset[int]
    log_likelihood: float
    scores: tuple[tuple[int, RowCandidates, np.ndarray, np.ndarray], ...]  # per row: candidates, p, novelty


def planned_rows(space: TaskSpace, hand_width: float) -> list[Row]:
    """The rows the hand crosses on its way: beyond the start, before it reaches the target (whose
    near face it stops ``REACH_FRACTION`` hand widths short of; measured in the VR trials, a row
    whose centre lies further on is not crossed: the hand reaches the target beside it)."""
    scene = space.scene
    reach = scene.target.x - scene.target.size[0] / 2.0 - REACH_FRACTION * hand_width
    return [row for row in space.rows if scene.start[0] < row.x < reach]


FALLBACK_SCALE = 0.5
"""The one-line rule's shares fall by e for every this many hand widths a candidate lies further
from the hand's line than the nearest (``_fallback``)."""


def _fallback(candidates: RowCandidates) -> np.ndarray:
    """The one-line rule's choice as probabilities: the gap nearest the hand's line (else the
    obstacle nearest it), with the gaps about as near as alternatives: shares falling by e per
    ``FALLBACK_SCALE`` hand widths of lateral offset beyond the nearest. Two gaps equally near
    (the line meeting an obstacle in its middle) are then both followed and the plan's ranking
    chooses, where a hard nearest-gap rule would flip between them with sub-millimetre changes."""
    offset = candidates.X[:, 3] + 1e3 * candidates.X[:, 0]  # lateral offset in hand widths; gaps first
    p = np.exp(-(offset - offset.min()) / FALLBACK_SCALE)
    return p / p.sum()


class _Expander:
    """Grows partial plans by one row: Cr on the row's candidates, Cd for each obstacle moved."""

    def __init__(
        self, space: TaskSpace, models: DecisionModels, config: PlannerConfig, hand_width: float, mirror: bool
    ) -> None:
        self.space, self.models, self.config, self.width, self.mirror = (
            space,
            models,
            config,
            hand_width,
            mirror,
        )
        self.features = RowChoiceScene(space, hand_width)
        self.names = space.obstacle_names
        self.directions = DirectionTable(space, self.names, mode=config.mode)

    def candidates(
        self, beam: list[_Partial], row: Row
    ) -> list[tuple[RowCandidates, np.ndarray, np.ndarray]]:
        """Per partial plan: the row's candidates from its hand, their probabilities (summing to 1)
        and their novelty (Cr asked once for the whole beam); where no candidate lies within the
        demonstrations' range (novelty <= 1), the one-line rule's choice."""
        per_plan = self.features.candidates(
            row.index,
            np.array([p.hand for p in beam]),
            [p.removed for p in beam],
            mirror=self.mirror,
            limit=self.config.classify_per_row,
            previous=np.array([p.keypoints[-2 if len(p.keypoints) > 1 else -1].position for p in beam]),
            came_by=[p.keypoints[-1].action for p in beam],
        )
        X = np.vstack([c.X for c in per_plan])[:, : self.models.row.n_features_in_]
        probability = self.models.row.predict_proba(X)[:, 1] if len(X) else np.zeros(0)
        novelty = self.models.row.novelty(X) if len(X) else np.zeros(0)
        result, start = [], 0
        for candidates in per_plan:
            end = start + len(candidates)
            p = probability[start:end] if np.any(novelty[start:end] <= 1.0) else _fallback(candidates)
            result.append((candidates, p / max(float(p.sum()), 1e-300), novelty[start:end]))
            start = end
        return result

    def moves(self, hands: list[tuple[float, float]], obstacles: list[int]) -> list[str]:
        """Cd's direction for each obstacle approached from its hand (one prediction for all)."""
        if not obstacles:
            return []
        classes = [direction_index(d) for d in self.directions.hand_directions(obstacles, hands)]
        X = self.directions.features(np.asarray(obstacles, int), np.asarray(classes, int))
        return [
            DIRECTIONS[int(label)]
            for label in self.models.direction.predict(X.reshape(-1, len(DIRECTION_FEATURES)))
        ]

    def grow(self, beam: list[_Partial], row: Row) -> list[_Partial]:
        """Every partial plan of ``beam`` grown by its likely choices at ``row``."""
        chosen = []  # (partial, candidates, p, evidence, k) of every choice followed
        for partial, (candidates, p, evidence) in zip(beam, self.candidates(beam, row)):
            if len(candidates) == 0:
                chosen.append((partial, candidates, p, evidence, None))
                continue
            keep = [k for k in np.argsort(-p, kind="stable") if p[k] >= self.config.min_share] or [
                int(np.argmax(p))
            ]
            chosen += [(partial, candidates, p, evidence, int(k)) for k in keep]
        moved = [c for c in chosen if c[4] is not None and c[1].kinds[c[4]] == "object"]
        obstacles = [int(c[1].obstacles[c[4]]) for c in moved]
        directions = self.moves([c[0].hand for c in moved], obstacles)
        regions = self.space.relocated[obstacles]  # (moves, 8, 4)
        move_of = {
            id(c): (d, region[DIRECTIONS.index(d)]) for c, d, region in zip(moved, directions, regions)
        }
        children = []
        for choice in chosen:
            partial, candidates, p, evidence, k = choice
            scores = (*partial.scores, (row.index, candidates, p, evidence))
            if k is None:
                children.append(
                    _Partial(partial.keypoints, partial.hand, partial.removed, partial.log_likelihood, scores)
                )
                continue
            log_likelihood = partial.log_likelihood + math.log(max(float(p[k]), 1e-300))
            point = tuple(float(v) for v in candidates.points[k])
            element = candidates.element(k, self.names)
            if candidates.kinds[k] == "gap":
                keypoints = (*partial.keypoints, PlanKeypoint("gap", point, row.index, element))
                children.append(_Partial(keypoints, point, partial.removed, log_likelihood, scores))
                continue
            obstacle, (direction, region) = int(candidates.obstacles[k]), move_of[id(choice)]
            release = (float((region[0] + region[2]) / 2.0), float((region[1] + region[3]) / 2.0))
            keypoints = (
                *partial.keypoints,
                PlanKeypoint("move", point, row.index, element, direction),
                PlanKeypoint("release", release, row.index, element, direction),
            )
            children.append(
                _Partial(keypoints, release, partial.removed | {obstacle}, log_likelihood, scores)
            )
        return children


def segment_collisions(
    space: TaskSpace, keypoints: tuple[PlanKeypoint, ...], hand_width: float
) -> list[dict]:
    """The hand's straight ways between consecutive keypoints that pass through an obstacle, each as
    ``{"segment": i, "obstacle": name, "depth": m}``: the length of the way inside the obstacle
    grown by half the hand's width, the obstacles where they stand at that moment (a moved one at
    the centre of its relocated region from its release on, and not on the ways to and with it)."""
    return plans_segment_collisions(space, [keypoints], hand_width)[0]


def plans_segment_collisions(
    space: TaskSpace, plans: list[tuple[PlanKeypoint, ...]], hand_width: float
) -> list[list[dict]]:
    """``segment_collisions`` of each plan of ``plans``, with one segment test for all."""
    placed = [_placements(space, keypoints) for keypoints in plans]
    ends = [np.array([k.position for k in keypoints], dtype=float).reshape(-1, 2) for keypoints in plans]
    rects = np.vstack([np.array(r, dtype=float).reshape(-1, 4) for r, _, _ in placed])
    grown = rects + np.array([-hand_width, -hand_width, hand_width, hand_width]) / 2.0
    inside = segment_inside(
        np.vstack([e[:-1] for e in ends]).reshape(-1, 2),
        np.vstack([e[1:] for e in ends]).reshape(-1, 2),
        grown,
    )
    names, result, row, column = space.obstacle_names, [], 0, 0
    for (plan_rects, owners, counted), e in zip(placed, ends):
        segments, count = max(len(e) - 1, 0), len(plan_rects)
        own = inside[row : row + segments, column : column + count] * counted
        row, column = row + segments, column + count
        result.append(
            [
                {"segment": int(i), "obstacle": names[owners[r]], "depth": float(own[i, r])}
                for i, r in zip(*np.nonzero(own > 1e-9))
            ]
        )
    return result


def _placements(space: TaskSpace, keypoints: tuple[PlanKeypoint, ...]) -> tuple[list, list[int], np.ndarray]:
    """Every place an obstacle stands along a plan, the obstacle's position in scene order and the
    segments (keypoint to keypoint) it counts for there: (rects, owners, (segments, places)). The
    original places count until the obstacle's release, its relocated region after it; neither on
    the ways to and with it."""
    n, segments = len(space.obstacle_names), max(len(keypoints) - 1, 0)
    rects, owners, spans = list(space.obstacle_bounds), list(range(n)), [[0, segments]] * n
    own = np.zeros((segments, n), dtype=bool)  # the ways to and with the obstacle moved
    for i, (a, b) in enumerate(pairwise(keypoints)):
        for k in (a, b):
            if k.action in ("move", "release"):
                own[i, space.obstacle_index[k.element]] = True
        if b.action == "release":
            k = space.obstacle_index[b.element]
            spans[k] = [0, i + 1]
            rects.append(space.relocated[k][DIRECTIONS.index(b.direction)])
            owners.append(k)
            spans.append([i + 1, segments])
    spans_ = np.array(spans, dtype=int).reshape(-1, 2)
    j = np.arange(segments)[:, None]
    return rects, owners, (j >= spans_[:, 0]) & (j < spans_[:, 1]) & ~own[:, owners]


def plan_rows(
    space: TaskSpace,
    models: DecisionModels,
    config: PlannerConfig,
    q0: np.ndarray,
    links: tuple[float, float],
    hand_width: float,
    started: float,
) -> HighLevelPlan:
    """The row-by-row plan of a valid scene's task space (see the module docstring)."""
    scene = space.scene
    expander = _Expander(space, models, config, hand_width, mirror=False)
    start = PlanKeypoint("start", (float(scene.start[0]), float(scene.start[1])))
    beam = [_Partial((start,), start.position, frozenset(), 0.0, ())]
    for row in planned_rows(space, hand_width):
        grown = sorted(expander.grow(beam, row), key=lambda c: -c.log_likelihood)
        beam = grown[: config.beam]
    target = PlanKeypoint("target", space.target.center, None, scene.target.name)
    keypoints = [[*partial.keypoints, target] for partial in beam]
    tree = PrefixTree.of(keypoints)
    arms = arm_configurations(models, tree, q0, links[0] + links[1], False)
    costs = expected_collisions(space, tree, arms, links, config.arm_band, False)
    collisions = plans_segment_collisions(space, [tuple(k) for k in keypoints], hand_width)
    score = [
        beam[i].log_likelihood - config.collision_weight * sum(c["depth"] for c in collisions[i]) / hand_width
        for i in range(len(beam))
    ]
    order = sorted(range(len(beam)), key=lambda i: (-score[i], costs[i]))
    best = order[0]
    chosen = tuple(
        PlanKeypoint(k.action, k.position, k.row, k.element, k.direction, (float(q[0]), float(q[1])))
        for k, q in zip(keypoints[best], arms[[0, *tree.paths[best]]].tolist())
    )
    alternatives = tuple(PlanCandidate(tuple(keypoints[i]), costs[i]) for i in order[1:])
    details = _details(space, beam[best], [beam[i].log_likelihood for i in order])
    details["segment_collisions"] = collisions[best]
    return HighLevelPlan(
        scene.name, chosen, costs[best], alternatives, time.perf_counter() - started, None, details
    )


def _details(space: TaskSpace, partial: _Partial, log_likelihoods: list[float]) -> dict:
    """What the chosen plan's rows looked like: per candidate its probability minus one half
    (``gap_scores``, ``object_scores``: > 0 means Cr takes it, the evaluation's raw labels), the
    rows' candidates and their novelty, which rows' scores carried evidence (any candidate's
    novelty <= 1), and the beam's log-likelihoods."""
    names = space.obstacle_names
    gap_scores, object_scores, candidates, evidence, novelty = {}, {}, {}, {}, {}
    for row, row_candidates_, p, row_novelty in partial.scores:
        elements = [row_candidates_.element(k, names) for k in range(len(row_candidates_))]
        candidates[str(row)] = elements
        evidence[str(row)] = bool(np.any(row_novelty <= 1.0))
        novelty[str(row)] = [float(v) for v in row_novelty]
        for k, element in enumerate(elements):
            if row_candidates_.kinds[k] == "gap":
                gap_scores[f"{row}:{element}"] = float(p[k]) - 0.5
            else:
                object_scores[element] = float(p[k]) - 0.5
    return {
        "gap_scores": gap_scores,
        "object_scores": object_scores,
        "candidates": candidates,
        "evidence": evidence,
        "novelty": novelty,
        "log_likelihoods": log_likelihoods,
    }
