"""Row-choice classifier Cr: which candidate of a row (a gap or an obstacle) a person takes.

A binary classifier over the candidates' features (``hlp_drake.features.row_choice``): positive
for the candidate the person took. The planner ranks a row's candidates by it. Beyond a score it
gives a calibrated probability and a novelty score, so the planner knows when a case lies outside
the demonstrations.
"""

from __future__ import annotations

from typing import ClassVar

import numpy as np
from scipy.special import expit
from sklearn.base import BaseEstimator, ClassifierMixin
from sklearn.ensemble import GradientBoostingClassifier
from sklearn.linear_model import LogisticRegression
from sklearn.model_selection import GroupKFold, StratifiedKFold
from sklearn.utils.multiclass import check_classification_targets
from sklearn.utils.validation import check_is_fitted, validate_data

from hlp_drake.learners.conformance import SAMPLE_WEIGHT_EQUIVALENCE
from hlp_drake.learners.inputs import binary_classes, prediction_input, sample_weights
from hlp_drake.learners.kernel import distance_weights
from hlp_drake.learners.novelty import SAMPLES as NOVELTY_SAMPLES
from hlp_drake.learners.novelty import fit_novelty, novelty_score
from hlp_drake.learners.state import Spec
from hlp_drake.learners.svm import RbfSvmClassifier
from hlp_drake.learners.trees import BoostedTrees, boosted_tree_arrays

LEARNERS = ("boosted", "svm")


class RowChoiceClassifier(ClassifierMixin, BaseEstimator):
    """Calibrated binary classifier with a novelty score.

    Args:
        learner: "boosted" (gradient-boosted trees, the default) or "svm" (the paper's RBF SVM on
            standardised features).
        n_estimators, max_depth, learning_rate, subsample: the boosted trees' settings.
        C, kernel_scale: the SVM's settings (as ``RbfSvmClassifier``).
        calibration_folds: folds of the cross-validated scores a Platt (logistic) calibration is
            fitted on (by the ``groups`` given to ``fit``, e.g. subjects, else stratified).
        novelty_neighbours, novelty_quantile, novelty_samples: see ``learners.novelty``.
        random_state: seed of the subsamples and folds.
    """

    NOVELTY: ClassVar[dict[str, Spec]] = {
        "mean": ("float64", ("n_features",)),
        "scale": ("float64", ("n_features",)),
        "points": ("float64", ("n_points", "n_features")),
        "neighbours": ("int64", ()),
        "threshold": ("float64", ()),
    }
    """The novelty model's arrays (``novelty.*`` of ``get_state``): dtype and shape."""

    @staticmethod
    def state(learner: str) -> dict[str, Spec]:
        """The arrays of ``get_state`` with the ``learner`` ("boosted" or "svm"): dtype and shape,
        the row learner's and the novelty model's ``n_features`` one dimension."""
        inner = BoostedTrees.STATE if learner == "boosted" else RbfSvmClassifier.STATE
        return {
            "classes": ("float64", (2,)),
            "calibration": ("float64", (2,)),
            **{f"learner.{name}": spec for name, spec in inner.items()},
            **{f"novelty.{name}": spec for name, spec in RowChoiceClassifier.NOVELTY.items()},
        }

    EXPECTED_FAILED_CHECKS: ClassVar[dict[str, str]] = {
        SAMPLE_WEIGHT_EQUIVALENCE: (
            "the calibration folds, the trees' subsample and minimum node sizes count rows, not "
            "weights (as for scikit-learn's GradientBoostingClassifier); learner='svm': see "
            "RbfSvmClassifier"
        )
    }

    def __init__(
        self,
        learner: str = "boosted",
        n_estimators: int = 150,
        max_depth: int = 3,
        learning_rate: float = 0.1,
        subsample: float = 0.8,
        C: float = 1.0,
        kernel_scale: float = 0.25,
        calibration_folds: int = 2,
        novelty_neighbours: int = 5,
        novelty_quantile: float = 0.99,
        novelty_samples: int = NOVELTY_SAMPLES,
        random_state: int = 0,
    ) -> None:
        self.learner = learner
        self.n_estimators = n_estimators
        self.max_depth = max_depth
        self.learning_rate = learning_rate
        self.subsample = subsample
        self.C = C
        self.kernel_scale = kernel_scale
        self.calibration_folds = calibration_folds
        self.novelty_neighbours = novelty_neighbours
        self.novelty_quantile = novelty_quantile
        self.novelty_samples = novelty_samples
        self.random_state = random_state

    def __sklearn_tags__(self):
        tags = super().__sklearn_tags__()
        tags.classifier_tags.multi_class = False
        return tags

    def _learner(self):
        if self.learner == "boosted":
            return GradientBoostingClassifier(
                n_estimators=self.n_estimators,
                max_depth=self.max_depth,
                learning_rate=self.learning_rate,
                subsample=self.subsample,
                random_state=self.random_state,
            )
        if self.learner == "svm":
            return RbfSvmClassifier(C=self.C, kernel_scale=self.kernel_scale, random_state=self.random_state)
        raise ValueError(f"unknown learner {self.learner!r}; choose one of {', '.join(LEARNERS)}")

    def _fit_learner(
        self, X: np.ndarray, y: np.ndarray, sample_weight: np.ndarray | None
    ) -> BoostedTrees | RbfSvmClassifier:
        """Fit one learner: the boosted trees (as arrays), or the SVM."""
        model = self._learner().fit(X, y, sample_weight=sample_weight)
        return (
            BoostedTrees(boosted_tree_arrays(model, X))
            if isinstance(model, GradientBoostingClassifier)
            else model
        )

    def fit(
        self,
        X: np.ndarray,
        y: np.ndarray,
        sample_weight: np.ndarray | None = None,
        groups: np.ndarray | None = None,
    ) -> RowChoiceClassifier:
        """Fit on candidates ``X`` labelled ``y`` (two classes; the second is "taken").

        Args:
            sample_weight: per-row weights (e.g. to balance the structured and unstructured trials).
            groups: per-row group (subject) labels: the calibration's folds never split a group.
        """
        X, y = validate_data(self, X, y)
        check_classification_targets(y)
        self.classes_ = binary_classes(self, y)
        positive = (y == self.classes_[1]).astype(int)
        weight = sample_weights(sample_weight, len(y))
        oof = np.zeros(len(X))
        folds = self._folds(positive, groups, weight)
        for train, test in folds:
            learner = self._fit_learner(X[train], positive[train], None if weight is None else weight[train])
            oof[test] = learner.decision_function(X[test])
        platt = LogisticRegression(C=1e6).fit(oof[:, None], positive) if folds else None
        self.calibration_ = (
            np.array([float(platt.coef_[0, 0]), float(platt.intercept_[0])])
            if platt is not None
            else np.array([1.0, 0.0])
        )
        self._learner_ = self._fit_learner(X, positive, weight)
        rng = np.random.default_rng(self.random_state)
        self.novelty_ = fit_novelty(
            X,
            rng,
            samples=self.novelty_samples,
            neighbours=self.novelty_neighbours,
            quantile=self.novelty_quantile,
        )
        self._novelty_weights = distance_weights(self.novelty_["points"])
        return self

    def _folds(
        self, positive: np.ndarray, groups: np.ndarray | None, weight: np.ndarray | None = None
    ) -> list[tuple[np.ndarray, np.ndarray]]:
        """The calibration folds (only those whose training rows hold both classes with weight > 0)."""
        k = self.calibration_folds
        if groups is not None and len(np.unique(groups)) >= k:
            folds = list(GroupKFold(n_splits=k).split(positive, positive, groups))
        elif np.bincount(positive, minlength=2).min() >= k:
            folds = list(
                StratifiedKFold(n_splits=k, shuffle=True, random_state=self.random_state).split(
                    positive, positive
                )
            )
        else:
            return []
        weighted = np.ones(len(positive), dtype=bool) if weight is None else weight > 0
        return [(tr, te) for tr, te in folds if len(np.unique(positive[tr][weighted[tr]])) == 2]

    def decision_function(self, X: np.ndarray) -> np.ndarray:
        """The learner's raw score: > 0 leans to "taken" (``classes_[1]``)."""
        X = prediction_input(self, X)
        return self._learner_.decision_function(X)

    def predict_proba(self, X: np.ndarray) -> np.ndarray:
        """(n, 2) calibrated probabilities of ``classes_``."""
        score = self.decision_function(X)
        a, b = self.calibration_
        p = expit(a * score + b)  # the logistic function, without overflow for large scores
        return np.column_stack([1.0 - p, p])

    def predict(self, X: np.ndarray) -> np.ndarray:
        taken = self.predict_proba(X)[:, 1] > 0.5
        return self.classes_[taken.astype(int)]

    def novelty(self, X: np.ndarray) -> np.ndarray:
        """(n,) how far each case lies from the training cases (> 1: outside their usual range)."""
        return novelty_score(self.novelty_, self._novelty_weights, prediction_input(self, X))

    def get_state(self) -> dict[str, np.ndarray]:
        """The fitted arrays (for safe saving)."""
        check_is_fitted(self)
        state = {"classes": self.classes_, "calibration": self.calibration_}
        learner = (
            self._learner_.get_state()
            if isinstance(self._learner_, RbfSvmClassifier)
            else self._learner_.arrays
        )
        state.update({f"learner.{k}": v for k, v in learner.items()})
        state.update({f"novelty.{k}": v for k, v in self.novelty_.items()})
        return state

    def set_state(self, state: dict[str, np.ndarray]) -> RowChoiceClassifier:
        self.classes_, self.calibration_ = state["classes"], state["calibration"]
        learner = {k[len("learner.") :]: v for k, v in state.items() if k.startswith("learner.")}
        self._learner_ = (
            RbfSvmClassifier().set_state(learner) if self.learner == "svm" else BoostedTrees(learner)
        )
        self.novelty_ = {k[len("novelty.") :]: v for k, v in state.items() if k.startswith("novelty.")}
        self.n_features_in_ = len(self.novelty_["mean"])
        self._novelty_weights = distance_weights(self.novelty_["points"])
        return self
