"""Arm-configuration regressor Ra: the next (q1, q2) from the current one and the hand's move (5.3)."""

from __future__ import annotations

from typing import ClassVar

import numpy as np
from sklearn.base import BaseEstimator, RegressorMixin
from sklearn.gaussian_process import GaussianProcessRegressor
from sklearn.gaussian_process.kernels import RBF, ConstantKernel, WhiteKernel
from sklearn.utils.validation import check_is_fitted, validate_data

from hlp_drake.learners.encoding import N_DIRECTIONS, check_categorical, expand_directions
from hlp_drake.learners.inputs import prediction_input
from hlp_drake.learners.kernel import distance_weights, gaussian_kernel
from hlp_drake.learners.state import Spec

CATEGORICAL = (4,)  # direction class index in Xa


class ArmRegressor(RegressorMixin, BaseEstimator):
    """One Gaussian process per output (constant * RBF + white noise) on standardised inputs and
    outputs; the ``categorical`` columns (direction class indices) enter one-hot. For Ra:
    ``categorical=CATEGORICAL``.

    Args:
        max_samples: rows used for the fit (a random subset above it, as MATLAB's subset-of-data
            fit above 2000 rows); a GP's fit grows cubically with the rows.
        categorical: class-index columns of X.
        random_state: seed of the subset.

    Inputs are standardised (the original did not; one shared length scale then weighs angles,
    displacements and one-hot classes alike). Saved as plain arrays; prediction is the GP mean.
    """

    STATE: ClassVar[dict[str, Spec]] = {
        "mean": ("float64", ("n_encoded",)),
        "scale": ("float64", ("n_encoded",)),
        "train": ("float64", ("n_samples", "n_encoded")),
        "alpha": ("float64", ("n_outputs", "n_samples")),
        "length_scale": ("float64", ("n_outputs",)),
        "amplitude": ("float64", ("n_outputs",)),
        "y_mean": ("float64", ("n_outputs",)),
        "y_std": ("float64", ("n_outputs",)),
        "outputs": ("int64", ()),
    }
    """The arrays of ``get_state``: dtype and shape (``n_encoded``: the features after one-hot
    encoding)."""

    def __init__(
        self, max_samples: int = 1500, categorical: tuple[int, ...] = (), random_state: int = 0
    ) -> None:
        self.max_samples = max_samples
        self.categorical = categorical
        self.random_state = random_state

    def __sklearn_tags__(self):
        tags = super().__sklearn_tags__()
        tags.target_tags.multi_output = True
        return tags

    def fit(self, X: np.ndarray, y: np.ndarray) -> ArmRegressor:
        X, y = validate_data(self, X, y, multi_output=True, y_numeric=True)
        check_categorical(self.categorical, X.shape[1])
        self.n_outputs_ = 1 if y.ndim == 1 else y.shape[1]
        self._flat = y.ndim == 1  # predict as the target was given: (n,) or (n, outputs)
        y = y.reshape(len(y), -1).astype(float)
        rng = np.random.default_rng(self.random_state)
        if len(X) > self.max_samples:
            index = rng.choice(len(X), self.max_samples, replace=False)
            X, y = X[index], y[index]
        Z = expand_directions(X, self.categorical)
        self.mean_ = Z.mean(axis=0)
        self.scale_ = np.where(Z.std(axis=0) > 0, Z.std(axis=0), 1.0)
        self.train_ = (Z - self.mean_) / self.scale_
        self.y_mean_ = y.mean(axis=0)
        self.y_std_ = np.where(y.std(axis=0) > 0, y.std(axis=0), 1.0)
        targets = (y - self.y_mean_) / self.y_std_
        self.alpha_, self.length_scale_, self.amplitude_ = [], [], []
        for k in range(y.shape[1]):
            kernel = ConstantKernel(1.0) * RBF(length_scale=1.0) + WhiteKernel(0.1)
            gp = GaussianProcessRegressor(kernel, random_state=self.random_state).fit(
                self.train_, targets[:, k]
            )
            self.alpha_.append(gp.alpha_.ravel())
            self.length_scale_.append(gp.kernel_.k1.k2.length_scale)
            self.amplitude_.append(gp.kernel_.k1.k1.constant_value)
        self.alpha_ = np.array(self.alpha_)
        self.length_scale_ = np.array(self.length_scale_, dtype=float)
        self.amplitude_ = np.array(self.amplitude_, dtype=float)
        self._weights = distance_weights(self.train_)
        return self

    def predict(self, X: np.ndarray) -> np.ndarray:
        """(n, outputs) predictions; (n,) for a model fitted on a 1-D target."""
        X = prediction_input(self, X)
        q = self._predict(self._standardised(X))
        return q[:, 0] if self._flat else q

    def rollout(
        self,
        start: np.ndarray,
        parent: list[int],
        moves: np.ndarray,
        limits: tuple[float, float] = (-np.inf, np.inf),
    ) -> np.ndarray:
        """The angles at every node of a tree of hand moves, each predicted from its parent's.

        Args:
            start: (q1, q2) at node 0, the root.
            parent: each node's parent, an earlier node (node 0's is ignored).
            moves: (n, 3) the move into each node: (dx, dy) / arm length and its direction class.
            limits: the range predicted angles are clipped to.

        Returns:
            (n, 2) angles; one prediction covers all nodes of a depth.
        """
        depth = [0] * len(parent)
        for node in range(1, len(parent)):
            depth[node] = depth[parent[node]] + 1
        depth, parent = np.array(depth), np.asarray(parent)
        Z = self._standardised(prediction_input(self, np.column_stack([np.zeros((len(parent), 2)), moves])))
        q = np.zeros((len(parent), 2))
        q[0] = start
        for d in range(1, depth.max(initial=0) + 1):
            nodes = np.flatnonzero(depth == d)
            Z[nodes, :2] = (q[parent[nodes]] - self.mean_[:2]) / self.scale_[:2]
            q[nodes] = np.minimum(np.maximum(self._predict(Z[nodes]), limits[0]), limits[1])
        return q

    def _standardised(self, X: np.ndarray) -> np.ndarray:
        return (expand_directions(X, self.categorical) - self.mean_) / self.scale_

    def _predict(self, Z: np.ndarray) -> np.ndarray:
        kernels = gaussian_kernel(Z, self._weights, tuple(0.5 / self.length_scale_**2))
        return np.column_stack(
            [
                self.amplitude_[k] * (K @ self.alpha_[k]) * self.y_std_[k] + self.y_mean_[k]
                for k, K in enumerate(kernels)
            ]
        )

    def get_state(self) -> dict[str, np.ndarray]:
        check_is_fitted(self)
        return {
            "mean": self.mean_,
            "scale": self.scale_,
            "train": self.train_,
            "alpha": self.alpha_,
            "length_scale": self.length_scale_,
            "amplitude": self.amplitude_,
            "y_mean": self.y_mean_,
            "y_std": self.y_std_,
            "outputs": np.array(0 if self._flat else self.n_outputs_),
        }

    def set_state(self, state: dict[str, np.ndarray]) -> ArmRegressor:
        for name in ("mean", "scale", "train", "alpha", "length_scale", "amplitude", "y_mean", "y_std"):
            setattr(self, f"{name}_", state[name])
        self._flat = int(state["outputs"]) == 0
        self.n_outputs_ = len(self.y_mean_)
        self._weights = distance_weights(self.train_)
        self.n_features_in_ = self.train_.shape[1] - (N_DIRECTIONS - 1) * len(self.categorical)
        return self
