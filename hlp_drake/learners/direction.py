"""Direction classifier Cd: which way a person moves an obstacle (8 classes, reference 5.2)."""

from __future__ import annotations

from typing import ClassVar

import numpy as np
from sklearn.base import BaseEstimator, ClassifierMixin
from sklearn.svm import SVC
from sklearn.utils.multiclass import check_classification_targets
from sklearn.utils.validation import check_is_fitted, validate_data

from hlp_drake.learners.balance import oversample
from hlp_drake.learners.encoding import check_categorical, expand_directions
from hlp_drake.learners.inputs import prediction_input
from hlp_drake.learners.state import Spec
from hlp_drake.taskspace import DIRECTIONS

CATEGORICAL = (8, 9)  # hand_to_object, object_to_target class indices in Xd


class DirectionClassifier(ClassifierMixin, BaseEstimator):
    """One-vs-one linear SVM; the ``categorical`` columns (direction class indices, -1 for none)
    enter one-hot. For Cd: 8 free fractions + two direction classes (``categorical=CATEGORICAL``).

    Every class is oversampled to the largest; prediction is by one-vs-one votes (ties: the
    smaller class index).
    """

    STATE: ClassVar[dict[str, Spec]] = {
        "classes": ("float64", ("n_classes",)),
        "coef": ("float64", ("n_pairs", "n_encoded")),
        "intercept": ("float64", ("n_pairs",)),
    }
    """The arrays of ``get_state``: dtype and shape (``n_pairs``: the one-vs-one class pairs,
    ``n_encoded``: the features after one-hot encoding)."""

    def __init__(self, C: float = 1.0, categorical: tuple[int, ...] = (), random_state: int = 0) -> None:
        self.C = C
        self.categorical = categorical
        self.random_state = random_state

    def fit(self, X: np.ndarray, y: np.ndarray) -> DirectionClassifier:
        X, y = validate_data(self, X, y)
        check_classification_targets(y)
        check_categorical(self.categorical, X.shape[1])
        classes, codes = np.unique(y, return_inverse=True)
        Xb, yb = oversample(
            expand_directions(X, self.categorical), codes, np.random.default_rng(self.random_state)
        )
        svc = SVC(C=self.C, kernel="linear", decision_function_shape="ovo").fit(Xb, yb)
        self.classes_ = classes[svc.classes_]
        self.coef_ = svc.coef_
        self.intercept_ = svc.intercept_
        self._set_pairs()
        return self

    def _set_pairs(self) -> None:
        """(pairs, classes) indicators of the class each one-vs-one pair's positive and negative score
        votes for: libsvm's pairs (0, 1), (0, 2), ..., positive for the first; scikit-learn flips
        the single pair of a binary problem (positive: the second class)."""
        first, second = np.triu_indices(len(self.classes_), k=1)
        if len(self.classes_) == 2:
            first, second = second, first
        eye = np.eye(len(self.classes_))
        self._first, self._second = eye[first], eye[second]

    def votes(self, X: np.ndarray) -> np.ndarray:
        """(n, classes) one-vs-one votes."""
        X = prediction_input(self, X)
        scores = expand_directions(X, self.categorical) @ self.coef_.T + self.intercept_
        return (scores > 0) @ self._first + (scores <= 0) @ self._second

    def predict(self, X: np.ndarray) -> np.ndarray:
        best = np.argmax(self.votes(X), axis=1)
        return self.classes_[best]

    def get_state(self) -> dict[str, np.ndarray]:
        check_is_fitted(self)
        return {"classes": self.classes_, "coef": self.coef_, "intercept": self.intercept_}

    def set_state(self, state: dict[str, np.ndarray]) -> DirectionClassifier:
        self.classes_, self.coef_, self.intercept_ = state["classes"], state["coef"], state["intercept"]
        self.n_features_in_ = self.coef_.shape[1] - (len(DIRECTIONS) - 1) * len(self.categorical)
        self._set_pairs()
        return self
