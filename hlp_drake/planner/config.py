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
            line (this many of each) are classified, so the work per row is bounded however
            crowded the row is (a VR row has 4 gaps and 3 obstacles: all are classified).
    """

    mode: Mode = "fixed"
    max_gaps_per_row: int = 3
    max_objects_per_row: int = 2
    max_paths: int = 24
    min_gap_width: float = 0.0
    arm_band: float = 0.025
    classify_per_row: int = 6
    min_evidence: float = 0.05
