"""Typed settings of the human-like planner."""

from __future__ import annotations

import typing
from dataclasses import dataclass

from hlp_drake.documents import brief
from hlp_drake.segmentation.modes import Mode


@dataclass(frozen=True)
class PlannerConfig:
    """Settings of ``plan``.

    Attributes:
        mode: feature mode; must match the models' training mode.
        max_gaps_per_row, max_objects_per_row: at most this many accepted candidates per row
            (the best-scoring ones), so planning time depends on these caps, not on the number
            of objects. The original keeps every accepted candidate (with 3 obstacles a row
            never has more than 4 gaps and 3 obstacles).
        max_paths: at most this many candidate paths are rolled out (best segment scores first).
        min_gap_width: gaps narrower than this are never candidates (m; 0 keeps all, as the
            original).
        arm_band: half-width of the band swept by an arm link, m.
        min_evidence: a Cg, Co or Cc score closer than this to the classifier's intercept carries no
            evidence (the case lies outside the demonstrations' range): a row none of whose gap
            (obstacle) scores carries evidence keeps the one nearest the start-target line, and a
            pair of rows none of whose segment scores does keeps every segment between them (the
            arm's expected collision decides).
        classify_per_row: per row, only the gaps and obstacles laterally nearest the start-target
            line (the row-by-row planner: the hand's line to the target) (this many of each) are
            classified, so the work per row is bounded however crowded the row is (a VR row has 4
            gaps and 3 obstacles: all are classified).
        hand_width: the hand's (or gripper's) width the row-by-row planner measures in, m; None: the
            VR study's 5 cm hand scaled with the table (as the arm's link lengths are).
        beam: the row-by-row planner keeps this many partial plans from row to row.
        min_share: ... and follows a row's candidate only where its share of the row's choice
            probability is at least this (always the most likely one).
        collision_weight: the complete plans of the beam are ranked by their log-likelihood
            minus this times the length (in hand widths) of the hand's straight ways between
            keypoints inside obstacles (``row_plan.segment_collisions``).
    """

    mode: Mode = "fixed"
    max_gaps_per_row: int = 3
    max_objects_per_row: int = 2
    max_paths: int = 24
    min_gap_width: float = 0.0
    arm_band: float = 0.025
    classify_per_row: int = 6
    min_evidence: float = 0.05
    hand_width: float | None = None
    beam: int = 3
    min_share: float = 0.05
    collision_weight: float = 0.0


def planner_config_problems(config: PlannerConfig) -> list[str]:
    """Why ``config`` cannot be used (empty when it is fine): counts between 1 and 1000, lengths
    and weights finite and non-negative, shares in [0, 1]."""
    problems = []
    for name in ("max_gaps_per_row", "max_objects_per_row", "max_paths", "classify_per_row", "beam"):
        value = getattr(config, name)
        if not isinstance(value, int) or isinstance(value, bool) or not 1 <= value <= 1000:
            problems.append(f"{name} must be an integer between 1 and 1000, got {brief(value)}")
    numbers = {
        name: getattr(config, name)
        for name in ("min_gap_width", "arm_band", "min_evidence", "min_share", "collision_weight")
    }
    if config.hand_width is not None:
        numbers["hand_width"] = config.hand_width
    for name, value in numbers.items():
        ok = isinstance(value, int | float) and not isinstance(value, bool) and 0.0 <= value <= 1e6
        if not ok or (name == "min_share" and value > 1.0) or (name == "hand_width" and value <= 0.0):
            problems.append(f"{name} must be a finite number in range, got {brief(value)}")
    if config.mode not in typing.get_args(Mode):
        problems.append(f"mode must be one of {', '.join(typing.get_args(Mode))}, got {brief(config.mode)}")
    return problems
