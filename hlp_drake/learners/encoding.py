"""One-hot encoding of the direction-class columns of Xd and Xa (index -1 = undefined -> all zeros)."""

from __future__ import annotations

import numpy as np

N_DIRECTIONS = 8


def expand_directions(X: np.ndarray, columns: tuple[int, ...]) -> np.ndarray:
    """Replace the class-index ``columns`` of ``X`` by 8 one-hot columns each (appended at the end)."""
    X = np.asarray(X, dtype=float)
    keep = [c for c in range(X.shape[1]) if c not in columns]
    parts = [X[:, keep]]
    for c in columns:
        index = X[:, c].astype(int)
        hot = np.zeros((len(X), N_DIRECTIONS))
        valid = index >= 0
        hot[np.flatnonzero(valid), index[valid]] = 1.0
        parts.append(hot)
    return np.hstack(parts)
