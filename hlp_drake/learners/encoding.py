"""One-hot encoding of the direction-class columns of Xd and Xa (index -1 = undefined -> all zeros;
any value outside 0-7 likewise)."""

from __future__ import annotations

import numpy as np

N_DIRECTIONS = 8


def expand_directions(X: np.ndarray, columns: tuple[int, ...]) -> np.ndarray:
    """Replace the class-index ``columns`` of ``X`` by 8 one-hot columns each (appended at the end)."""
    X = np.asarray(X, dtype=float)
    keep = [c for c in range(X.shape[1]) if c not in columns]
    out = np.zeros((len(X), len(keep) + N_DIRECTIONS * len(columns)))
    out[:, : len(keep)] = X[:, keep]
    for k, c in enumerate(columns):
        index = X[:, c].astype(int)
        valid = np.flatnonzero((index >= 0) & (index < N_DIRECTIONS))
        out[valid, len(keep) + N_DIRECTIONS * k + index[valid]] = 1.0
    return out


def check_categorical(columns: tuple[int, ...], n_features: int) -> None:
    """Raise a ValueError unless every categorical column index is one of the ``n_features``."""
    outside = [c for c in columns if not 0 <= c < n_features]
    if outside:
        raise ValueError(f"categorical columns {outside} outside the {n_features} features")
