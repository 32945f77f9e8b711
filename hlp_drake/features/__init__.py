"""Decision features (reference notes section 4): Xg, Xo, Xd, Xc, Xa and the training sets.

Pure functions of a Scene's TaskSpace (plus the hand state for Xd and Xa), so the same code
describes demonstrations and new scenes.
"""

from hlp_drake.features.arm import ARM_FEATURES, arm_features
from hlp_drake.features.direction import DIRECTION_FEATURES, direction_features, direction_index
from hlp_drake.features.plane import paper_angle, table_diagonal
from hlp_drake.features.scene_features import GAP_FEATURES, OBJECT_FEATURES, gap_features, object_features
from hlp_drake.features.segment import SEGMENT_FEATURES, segment_feature_matrix, segment_features
from hlp_drake.features.training import LabelledSet, TrainingData, training_data

__all__ = [
    "ARM_FEATURES",
    "DIRECTION_FEATURES",
    "GAP_FEATURES",
    "OBJECT_FEATURES",
    "SEGMENT_FEATURES",
    "LabelledSet",
    "TrainingData",
    "arm_features",
    "direction_features",
    "direction_index",
    "gap_features",
    "object_features",
    "paper_angle",
    "segment_feature_matrix",
    "segment_features",
    "table_diagonal",
    "training_data",
]
