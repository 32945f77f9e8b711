"""RBF-kernel SVM classifier of the paper (gap Cg, object Co and segment Cc classifiers)."""

from __future__ import annotations

from typing import ClassVar

import numpy as np
from sklearn.base import BaseEstimator, ClassifierMixin
from sklearn.svm import SVC
from sklearn.utils.multiclass import check_classification_targets
from sklearn.utils.validation import check_is_fitted, validate_data

from hlp_drake.learners.balance import oversample
from hlp_drake.learners.conformance import SAMPLE_WEIGHT_EQUIVALENCE
from hlp_drake.learners.inputs import binary_classes, prediction_input, sample_weights
from hlp_drake.learners.kernel import distance_weights, gaussian_kernel
from hlp_drake.learners.state import Spec


class RbfSvmClassifier(ClassifierMixin, BaseEstimator):
    """Binary RBF SVM on standardised features with minority oversampling (reference 5.1).

    Args:
        C: box constraint (the original: 1).
        kernel_scale: MATLAB's KernelScale; gamma = 1 / kernel_scale**2 (the original: 0.25 -> 16).
        max_per_class: rows per class after balancing at most (large classes are subsampled
            first); None balances to the largest class as the original. An RBF SVM's fit grows
            quadratically with the rows, so the segment classifier uses a cap.
        balance: oversample the minority class (the original); False fits the natural mix.
        random_state: seed of the oversampling.

    The fitted model keeps only plain arrays (scaler, support vectors, dual coefficients), so
    ``decision_function`` is reproduced exactly from a saved file.
    """

    STATE: ClassVar[dict[str, Spec]] = {
        "classes": ("float64", (2,)),
        "mean": ("float64", ("n_features",)),
        "scale": ("float64", ("n_features",)),
        "gamma": ("float64", ()),
        "support_vectors": ("float64", ("n_support", "n_features")),
        "dual_coef": ("float64", ("n_support",)),
        "intercept": ("float64", ()),
    }
    """The arrays of ``get_state``: dtype and shape."""

    EXPECTED_FAILED_CHECKS: ClassVar[dict[str, str]] = {
        SAMPLE_WEIGHT_EQUIVALENCE: (
            "libsvm stops at tol=1e-3, so a weight (a scaled C) and repeated rows reach different "
            "near-optimal solutions, as for scikit-learn's SVC; the oversampling and the "
            "standardisation also count rows, not weights"
        )
    }

    def __init__(
        self,
        C: float = 1.0,
        kernel_scale: float = 0.25,
        max_per_class: int | None = None,
        balance: bool = True,
        random_state: int = 0,
    ) -> None:
        self.C = C
        self.kernel_scale = kernel_scale
        self.max_per_class = max_per_class
        self.balance = balance
        self.random_state = random_state

    def __sklearn_tags__(self):
        tags = super().__sklearn_tags__()
        tags.classifier_tags.multi_class = False
        return tags

    def fit(self, X: np.ndarray, y: np.ndarray, sample_weight: np.ndarray | None = None) -> RbfSvmClassifier:
        X, y = validate_data(self, X, y)
        check_classification_targets(y)
        self.classes_ = binary_classes(self, y)
        rng = np.random.default_rng(self.random_state)
        rows = (
            oversample(np.arange(len(y)), y, rng, self.max_per_class)[0]
            if self.balance
            else np.arange(len(y))
        )
        Xb, yb = X[rows], y[rows]
        self.mean_ = Xb.mean(axis=0)
        self.scale_ = np.where(Xb.std(axis=0) > 0, Xb.std(axis=0), 1.0)
        self.gamma_ = 1.0 / self.kernel_scale**2
        svc = SVC(C=self.C, kernel="rbf", gamma=self.gamma_, cache_size=500)
        weight = sample_weights(sample_weight, len(y))
        weight = None if weight is None else weight[rows]
        svc.fit((Xb - self.mean_) / self.scale_, yb == self.classes_[1], sample_weight=weight)
        self.support_vectors_ = svc.support_vectors_
        self.dual_coef_ = svc.dual_coef_[0]
        self.intercept_ = float(svc.intercept_[0])
        self._weights = distance_weights(self.support_vectors_)
        return self

    def decision_function(self, X: np.ndarray) -> np.ndarray:
        """Signed distance-like score; > 0 means the positive class (``classes_[1]``)."""
        X = prediction_input(self, X)
        (kernel,) = gaussian_kernel((X - self.mean_) / self.scale_, self._weights, (self.gamma_,))
        return kernel @ self.dual_coef_ + self.intercept_

    def predict(self, X: np.ndarray) -> np.ndarray:
        positive = self.decision_function(X) > 0
        return self.classes_[positive.astype(int)]

    def get_state(self) -> dict[str, np.ndarray]:
        """The fitted arrays (for safe saving)."""
        check_is_fitted(self)
        return {
            "classes": self.classes_,
            "mean": self.mean_,
            "scale": self.scale_,
            "gamma": np.array(self.gamma_),
            "support_vectors": self.support_vectors_,
            "dual_coef": self.dual_coef_,
            "intercept": np.array(self.intercept_),
        }

    def set_state(self, state: dict[str, np.ndarray]) -> RbfSvmClassifier:
        self.classes_, self.mean_, self.scale_ = state["classes"], state["mean"], state["scale"]
        self.gamma_, self.intercept_ = float(state["gamma"]), float(state["intercept"])
        self.support_vectors_, self.dual_coef_ = state["support_vectors"], state["dual_coef"]
        self._weights = distance_weights(self.support_vectors_)
        self.n_features_in_ = len(self.mean_)
        return self
