"""Arm-configuration regressor Ra: the next (q1, q2) from the current one and the hand's move (5.3)."""

from __future__ import annotations

import numpy as np
from sklearn.base import BaseEstimator, RegressorMixin
from sklearn.gaussian_process import GaussianProcessRegressor
from sklearn.gaussian_process.kernels import RBF, ConstantKernel, WhiteKernel
from sklearn.utils.validation import check_is_fitted, validate_data

from hlp_drake.learners.inputs import prediction_input

from hlp_drake.learners.encoding import expand_directions

CATEGORICAL = (4,)  # direction class index in Xa


class ArmRegressor(RegressorMixin, BaseEstimator):
    """One Gaussian process per output angle (constant * RBF + white noise, fitted mean).

    Args:
        max_samples: rows used for the fit (a random subset above it, as MATLAB's subset-of-data
            fit above 2000 rows); a GP's fit grows cubically with the rows.
        random_state: seed of the subset.

    Inputs are standardised (the original did not; one shared length scale then weighs angles,
    displacements and one-hot classes alike). Saved as plain arrays; prediction is the GP mean.
    """

    def __init__(self, max_samples: int = 1500, random_state: int = 0) -> None:
        self.max_samples = max_samples
        self.random_state = random_state

    def fit(self, X: np.ndarray, y: np.ndarray) -> ArmRegressor:
        X, y = validate_data(self, X, y, multi_output=True)
        y = y.reshape(len(y), -1)
        rng = np.random.default_rng(self.random_state)
        if len(X) > self.max_samples:
            index = rng.choice(len(X), self.max_samples, replace=False)
            X, y = X[index], y[index]
        Z = expand_directions(X, CATEGORICAL)
        self.mean_ = Z.mean(axis=0)
        self.scale_ = np.where(Z.std(axis=0) > 0, Z.std(axis=0), 1.0)
        Z = (Z - self.mean_) / self.scale_
        self.train_ = Z
        self.alpha_, self.length_scale_, self.amplitude_, self.y_mean_, self.y_std_ = [], [], [], [], []
        for k in range(y.shape[1]):
            kernel = ConstantKernel(1.0) * RBF(length_scale=1.0) + WhiteKernel(0.1)
            gp = GaussianProcessRegressor(kernel, normalize_y=True, random_state=self.random_state).fit(Z, y[:, k])
            self.alpha_.append(gp.alpha_.ravel())
            self.length_scale_.append(gp.kernel_.k1.k2.length_scale)
            self.amplitude_.append(gp.kernel_.k1.k1.constant_value)
            self.y_mean_.append(gp._y_train_mean)
            self.y_std_.append(gp._y_train_std)
        self.alpha_ = np.array(self.alpha_)
        self.length_scale_ = np.array(self.length_scale_, dtype=float)
        self.amplitude_ = np.array(self.amplitude_, dtype=float)
        self.y_mean_ = np.array(self.y_mean_, dtype=float).ravel()
        self.y_std_ = np.array(self.y_std_, dtype=float).ravel()
        return self

    def predict(self, X: np.ndarray) -> np.ndarray:
        """(n, outputs) predicted angles."""
        X = prediction_input(self, X)
        Z = (expand_directions(X, CATEGORICAL) - self.mean_) / self.scale_
        sq = (Z**2).sum(1)[:, None] + (self.train_**2).sum(1)[None, :] - 2.0 * Z @ self.train_.T
        sq = np.clip(sq, 0.0, None)
        out = []
        for k in range(len(self.alpha_)):
            K = self.amplitude_[k] * np.exp(-0.5 * sq / self.length_scale_[k] ** 2)
            out.append((K @ self.alpha_[k]) * self.y_std_[k] + self.y_mean_[k])
        return np.column_stack(out)

    def get_state(self) -> dict[str, np.ndarray]:
        check_is_fitted(self)
        return {"mean": self.mean_, "scale": self.scale_, "train": self.train_, "alpha": self.alpha_,
                "length_scale": self.length_scale_, "amplitude": self.amplitude_, "y_mean": self.y_mean_,
                "y_std": self.y_std_}

    def set_state(self, state: dict[str, np.ndarray]) -> ArmRegressor:
        for name in ("mean", "scale", "train", "alpha", "length_scale", "amplitude", "y_mean", "y_std"):
            setattr(self, f"{name}_", state[name])
        self.n_features_in_ = 5
        return self
