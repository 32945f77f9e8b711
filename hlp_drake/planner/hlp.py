"""The human-like planner: row by row (``row_plan``), or Algorithm 1 of the paper (reference 6)."""

from __future__ import annotations

import time
from typing import TYPE_CHECKING

import numpy as np

from hlp_drake.config.ranges import config_problems
from hlp_drake.errors import SceneError, short
from hlp_drake.features import table_diagonal
from hlp_drake.features.row_choice import HUMAN_HAND_WIDTH
from hlp_drake.planner.blas import single_blas_thread
from hlp_drake.planner.candidates import classify, enumerate_paths, informed, row_candidates, segment_scores
from hlp_drake.planner.config import PlannerConfig
from hlp_drake.planner.plan import HighLevelPlan, PlanCandidate, PlanKeypoint
from hlp_drake.planner.rollout import PrefixTree, arm_configurations, expected_collisions, path_keypoints
from hlp_drake.planner.row_plan import plan_rows
from hlp_drake.scene.generators import VR_TABLE
from hlp_drake.scene.model import Scene
from hlp_drake.scene.validation import scene_problems
from hlp_drake.segmentation.modes import is_faithful
from hlp_drake.taskspace import TaskSpace

if TYPE_CHECKING:
    from hlp_drake.learners.models import DecisionModels


def _no_plan(scene: Scene, reason: str, started: float) -> HighLevelPlan:
    name = getattr(scene, "name", "") if isinstance(scene, Scene) else ""
    return HighLevelPlan(
        name if isinstance(name, str) else "",
        (),
        reason=short(reason, 2000),
        planning_time_s=time.perf_counter() - started,
    )


def plan(
    scene: Scene,
    models: DecisionModels,
    config: PlannerConfig | None = None,
    *,
    start_arm: tuple[float, float] | None = None,
    link_lengths: tuple[float, float] | None = None,
) -> HighLevelPlan:
    """Plan how a person would reach the target of ``scene``.

    The models decide the planner: the row-by-row planner (``planner.row_plan``) for models of the
    "rows" planner (the default presets), the paper's Algorithm 1 for the "paper" preset.

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
    problems = scene_problems(scene)
    if problems:
        return _no_plan(scene, "invalid scene: " + "; ".join(SceneError(*problems).problems), started)
    config = config or PlannerConfig(mode=models.mode_)
    reasons = config_problems(config) if isinstance(config, PlannerConfig) else ["not a PlannerConfig"]
    if reasons:
        return _no_plan(scene, "invalid planner settings: " + "; ".join(reasons), started)
    if config.mode != models.mode_:
        return _no_plan(
            scene, f"models were trained in {models.mode_} mode, the planner runs in {config.mode}", started
        )
    scale = table_diagonal(scene.table) / table_diagonal(VR_TABLE)  # arm lengths scale with the table
    links = link_lengths if link_lengths is not None else tuple(np.asarray(models.link_lengths_) * scale)
    q0 = np.asarray(start_arm if start_arm is not None else models.start_arm_, float)
    with single_blas_thread():
        space = TaskSpace(scene)
        if models.planner == "rows":
            width = config.hand_width if config.hand_width is not None else HUMAN_HAND_WIDTH * scale
            return plan_rows(space, models, config, q0, links, width, started)
        return _plan(space, models, config, q0, links, started)


def _plan(
    space: TaskSpace,
    models: DecisionModels,
    config: PlannerConfig,
    q0: np.ndarray,
    links: tuple[float, float],
    started: float,
) -> HighLevelPlan:
    """Steps 1-6 of ``plan`` on a valid scene's task space."""
    faithful = is_faithful(config.mode)

    # 1-3. Gaps and obstacles classified (per row the ones nearest the start-target line), the
    # accepted candidates per row, the segments between consecutive rows and the paths along them.
    gap_scores, object_scores = classify(space, models, config.classify_per_row)
    table, names = space.gap_table, space.obstacle_names
    details = {
        "gap_scores": {
            f"{r}:{i}": s
            for r, i, s in zip(table.row.tolist(), table.index.tolist(), gap_scores.tolist())
            if np.isfinite(s)
        },
        "object_scores": {n: s for n, s in zip(names, object_scores.tolist()) if np.isfinite(s)},
    }
    candidates = row_candidates(space, models, gap_scores, object_scores, config)
    blocks = segment_scores(space, models, candidates, config)
    evidence = [informed(block, models.segment.intercept_, config.min_evidence) for block in blocks]
    scored = enumerate_paths([len(c) for c in candidates], blocks, config.max_paths, evidence)

    # 4-5. Keypoints per path (moved obstacles' directions by Cd), arm configurations by Ra and
    # the arm's expected collision.
    keypoints = path_keypoints(space, models, candidates, [nodes for nodes, _ in scored], config.mode)
    tree = PrefixTree.of(keypoints)
    arms = arm_configurations(models, tree, q0, links[0] + links[1], faithful)
    costs = expected_collisions(space, tree, arms, links, config.arm_band, faithful)

    # 6. The path with the least expected collision (ties: the first).
    best = min(range(len(keypoints)), key=lambda i: costs[i])
    chosen = tuple(
        PlanKeypoint(
            k.action,
            (float(k.position[0]), float(k.position[1])),
            k.row,
            k.element,
            k.direction,
            (float(q[0]), float(q[1])),
        )
        for k, q in zip(keypoints[best], arms[[0, *tree.paths[best]]].tolist())
    )
    alternatives = tuple(
        sorted(
            (PlanCandidate(tuple(k), c) for i, (k, c) in enumerate(zip(keypoints, costs)) if i != best),
            key=lambda c: c.expected_collision,
        )
    )
    details["candidates"] = {str(r + 1): [n.element for n in c] for r, c in enumerate(candidates)}
    return HighLevelPlan(
        space.scene.name, chosen, costs[best], alternatives, time.perf_counter() - started, None, details
    )
