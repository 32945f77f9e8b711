"""Demonstration segmentation (reference notes section 3): per-row decisions, keypoints, arm angles."""

from hlp_drake.runtime.exports import lazy_exports

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

# Imported on first use: the planner settings (which a rollout worker reads) need ``modes`` alone, not
# the dataset and progress bars of batch segmentation.
__getattr__, __dir__ = lazy_exports(
    __name__,
    {
        "hlp_drake.segmentation.arm": ("LinkLengths", "arm_angles", "link_lengths", "medial_direction"),
        "hlp_drake.segmentation.batch": ("SegmentationResult", "demonstration_records", "segment_dataset"),
        "hlp_drake.segmentation.demonstration": (
            "GAP",
            "OBJECT",
            "Demonstration",
            "Keypoint",
            "Rejection",
            "RowDecision",
        ),
        "hlp_drake.segmentation.modes": ("DEFAULT_MODE", "MODES", "Mode", "check_mode", "is_faithful"),
        "hlp_drake.segmentation.segment": ("Rejected", "segment_trial"),
    },
)
