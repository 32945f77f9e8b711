"""Decision learners (reference section 5) as scikit-learn estimators, and their safe persistence."""

from hlp_drake.learners.arm import ArmRegressor
from hlp_drake.learners.choice import RowChoiceClassifier
from hlp_drake.learners.conformance import expected_failed_checks
from hlp_drake.learners.direction import DirectionClassifier
from hlp_drake.learners.models import DEFAULT_PRESET, PRESETS, DecisionModels, LearnerSettings
from hlp_drake.learners.svm import RbfSvmClassifier

__all__ = [
    "DEFAULT_PRESET",
    "PRESETS",
    "ArmRegressor",
    "DecisionModels",
    "DirectionClassifier",
    "LearnerSettings",
    "RbfSvmClassifier",
    "RowChoiceClassifier",
    "expected_failed_checks",
]
