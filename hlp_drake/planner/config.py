"""Typed settings of the human-like planner."""

from __future__ import annotations

from dataclasses import dataclass

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
