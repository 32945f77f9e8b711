"""Gaussian (RBF) kernel rows for the learners' predictions: squared distances in one matrix product."""

from __future__ import annotations

import numpy as np

EXPONENT_FLOOR = -700.0  # exp() of less is below 1e-304 and takes numpy's slow subnormal path: floored


def distance_weights(points: np.ndarray) -> np.ndarray:
    """(k + 2, m) weights W with [z, 1, |z|^2] @ W = |z - t|^2 for the m rows t of ``points`` (m, k)."""
    t = np.asarray(points, dtype=float)
    return np.vstack([-2.0 * t.T, (t**2).sum(1), np.ones(len(t))])


def gaussian_kernel(Z: np.ndarray, weights: np.ndarray, scales: tuple[float, ...]) -> list[np.ndarray]:
    """Per scale s, the (n, m) kernel exp(-s |z - t|^2) between the rows of ``Z`` (n, k) and the
    points behind ``weights`` (``distance_weights``)."""
    sq = np.column_stack([Z, np.ones(len(Z)), (Z**2).sum(1)]) @ weights
    np.maximum(sq, 0.0, out=sq)  # rounding can leave a distance slightly below 0
    largest = sq.max(initial=0.0)
    kernels = []
    for i, s in enumerate(scales):
        exponent = np.multiply(sq, -s, out=sq if i == len(scales) - 1 else None)
        if s * largest > -EXPONENT_FLOOR:
            np.maximum(exponent, EXPONENT_FLOOR, out=exponent)
        kernels.append(np.exp(exponent, out=exponent))
    return kernels
