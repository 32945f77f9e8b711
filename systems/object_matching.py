"""Which object of one scene is which of another, by position rather than by name.

Perceived objects are named by their order on the table (``object_1``, ...), which the next frame
may swap for two objects at almost the same x; comparing scenes by name would then see objects jump.
``match_obstacles`` pairs two sets of centres by least total distance (scipy's
``linear_sum_assignment``); the targets are each other.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import linear_sum_assignment


def match_obstacles(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(indices into ``a``, indices into ``b``, their distances) of the pairing of the (n, 2+) and
    (m, 2+) centres ``a`` and ``b`` with least total horizontal distance (min(n, m) pairs)."""
    if len(a) == 0 or len(b) == 0:
        empty = np.zeros(0, int)
        return empty, empty, np.zeros(0)
    a, b = np.asarray(a, float), np.asarray(b, float)
    cost = np.linalg.norm(a[:, None, :2] - b[None, :, :2], axis=2)
    rows, cols = linear_sum_assignment(cost)
    return rows, cols, cost[rows, cols]


def largest_displacement(expected: np.ndarray, observed: np.ndarray) -> float:
    """How far the object that moved most has gone from ``expected`` (m, m >= 1 rows of x, y[, z],
    the target first) to ``observed`` (the same form), the obstacles paired by ``match_obstacles``;
    infinite if the obstacles' counts differ (an object appeared or went)."""
    expected, observed = np.asarray(expected, float), np.asarray(observed, float)
    if len(expected) != len(observed):
        return float("inf")
    target = float(np.hypot(*(observed[0, :2] - expected[0, :2])))
    _, _, distances = match_obstacles(expected[1:], observed[1:])
    return max([target, *distances.tolist()])
