"""The VR human-demonstration dataset of Hasan et al. (ICRA 2020), in the project's world frame."""

from hlp_drake.dataset.dataset import Dataset
from hlp_drake.dataset.records import (
    CATEGORIES,
    PRACTICE,
    STRUCTURED,
    TRACKERS,
    UNSTRUCTURED,
    Interaction,
    Track,
    Trial,
    TrialRecord,
    category_of,
)
from hlp_drake.dataset.source import ENV_VAR, resolve_source

__all__ = [
    "CATEGORIES",
    "ENV_VAR",
    "PRACTICE",
    "STRUCTURED",
    "TRACKERS",
    "UNSTRUCTURED",
    "Dataset",
    "Interaction",
    "Track",
    "Trial",
    "TrialRecord",
    "category_of",
    "resolve_source",
]
