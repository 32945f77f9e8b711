"""How far a case lies from the demonstrations: the distance to its k-th nearest training example.

Features are standardised with the training set's mean and spread; a seeded sample of the
training rows is kept. ``score`` is the distance to the k-th nearest of them divided by the same
distance's ``quantile`` over other training rows (a second sample, as far from the kept ones as a
new case from the same source; with too few rows, the kept ones each left out of their own
neighbours), so a score above 1 means "further from the demonstrations than all but
(1 - quantile) of them are".
"""

from __future__ import annotations

import numpy as np

from hlp_drake.learners.kernel import distance_weights

SAMPLES = 1000
"""Points a novelty model keeps at most (``RowChoiceClassifier``'s default ``novelty_samples``)."""


def _kth_distance(Z: np.ndarray, weights: np.ndarray, k: int, exclude_self: bool = False) -> np.ndarray:
    sq = np.column_stack([Z, np.ones(len(Z)), (Z**2).sum(1)]) @ weights
    np.maximum(sq, 0.0, out=sq)
    if exclude_self:
        np.fill_diagonal(sq, np.inf)
    k = min(k, sq.shape[1] - int(exclude_self)) - 1
    return np.sqrt(np.partition(sq, k, axis=1)[:, k])


def fit_novelty(
    X: np.ndarray, rng: np.random.Generator, *, samples: int, neighbours: int, quantile: float
) -> dict[str, np.ndarray]:
    """The arrays of a novelty model of the rows of ``X``."""
    mean = X.mean(axis=0)
    scale = np.where(X.std(axis=0) > 0, X.std(axis=0), 1.0)
    Z = (X - mean) / scale
    order = rng.permutation(len(Z))
    kept, probe = Z[np.sort(order[:samples])], Z[np.sort(order[samples : 2 * samples])]
    weights = distance_weights(kept)
    if len(probe) >= samples // 2 and len(probe) > 0:
        distances = _kth_distance(probe, weights, neighbours)
    else:
        distances = (
            _kth_distance(kept, weights, neighbours, exclude_self=True) if len(kept) > 1 else np.zeros(1)
        )
    return {
        "mean": mean,
        "scale": scale,
        "points": kept,
        "neighbours": np.array(neighbours),
        "threshold": np.array(max(float(np.quantile(distances, quantile)), 1e-9)),
    }


def novelty_score(state: dict[str, np.ndarray], weights: np.ndarray, X: np.ndarray) -> np.ndarray:
    """(n,) distance of each row of ``X`` to its k-th nearest kept example / the threshold
    (``weights``: ``distance_weights(state["points"])``)."""
    Z = (np.asarray(X, float) - state["mean"]) / state["scale"]
    distance = _kth_distance(Z, weights, int(state["neighbours"]))
    return distance / float(state["threshold"])
