"""Demonstration segmentation (reference notes section 3): per-row decisions, keypoints, arm angles."""

from hlp_drake.segmentation.arm import LinkLengths, arm_angles, link_lengths, medial_direction
from hlp_drake.segmentation.batch import SegmentationResult, demonstration_records, segment_dataset
from hlp_drake.segmentation.demonstration import (
    GAP,
    OBJECT,
    Demonstration,
    Keypoint,
    Rejection,
    RowDecision,
)
from hlp_drake.segmentation.modes import DEFAULT_MODE, MODES, Mode, check_mode, is_faithful
from hlp_drake.segmentation.segment import Rejected, segment_trial

__all__ = [
    "DEFAULT_MODE",
    "GAP",
    "MODES",
    "OBJECT",
    "Demonstration",
    "Keypoint",
    "LinkLengths",
    "Mode",
    "Rejected",
    "Rejection",
    "RowDecision",
    "SegmentationResult",
    "arm_angles",
    "check_mode",
    "demonstration_records",
    "is_faithful",
    "link_lengths",
    "medial_direction",
    "segment_dataset",
    "segment_trial",
]
