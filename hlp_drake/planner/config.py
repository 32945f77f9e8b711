"""Typed settings of the human-like planner, each with its range (``hlp_drake.config.ranges``)."""

from __future__ import annotations

import typing
from dataclasses import dataclass
from typing import Annotated

from hlp_drake.config.ranges import Rule
from hlp_drake.files.documents import brief
from hlp_drake.segmentation.modes import Mode


def _is_number(value: object, upper: float = 1e6) -> bool:
    """Whether ``value`` is a number from 0 to ``upper`` (not a bool; NaN is not)."""
    return isinstance(value, int | float) and not isinstance(value, bool) and 0.0 <= value <= upper


COUNT = Rule(
    lambda v: isinstance(v, int) and not isinstance(v, bool) and 1 <= v <= 1000,
    "{where} must be an integer between 1 and 1000, got {value}",
    brief,
)
"""A count of candidates, paths or plans: 1 to 1000."""
NUMBER = Rule(_is_number, "{where} must be a finite number in range, got {value}", brief)
"""A length, evidence or weight: 0 to 1e6."""
SHARE = Rule(lambda v: _is_number(v, 1.0), NUMBER.message, brief)
POSITIVE_NUMBER = Rule(lambda v: _is_number(v) and v > 0.0, NUMBER.message, brief)
MODE = Rule(
    lambda v: v in typing.get_args(Mode),
    f"{{where}} must be one of {', '.join(typing.get_args(Mode))}, got {{value}}",
    brief,
)


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

    mode: Annotated[Mode, MODE] = "fixed"
    max_gaps_per_row: Annotated[int, COUNT] = 3
    max_objects_per_row: Annotated[int, COUNT] = 2
    max_paths: Annotated[int, COUNT] = 24
    min_gap_width: Annotated[float, NUMBER] = 0.0
    arm_band: Annotated[float, NUMBER] = 0.025
    classify_per_row: Annotated[int, COUNT] = 6
    min_evidence: Annotated[float, NUMBER] = 0.05
    hand_width: Annotated[float | None, POSITIVE_NUMBER] = None
    beam: Annotated[int, COUNT] = 3
    min_share: Annotated[float, SHARE] = 0.05
    collision_weight: Annotated[float, NUMBER] = 0.0
