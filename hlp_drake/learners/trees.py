"""Boosted decision trees as plain arrays: fitted by scikit-learn, evaluated here, saved as NPZ.

``GradientBoostingClassifier`` exposes its trees (``estimators_``, each ``tree_`` with its node
arrays); copying those arrays makes a fitted model a handful of numbers that load without pickle
and predict the same on any scikit-learn version.
"""

from __future__ import annotations

import numpy as np
from sklearn.ensemble import GradientBoostingClassifier

LEAF = -1  # child index of a leaf (scikit-learn's TREE_LEAF)


def boosted_tree_arrays(model: GradientBoostingClassifier, X: np.ndarray) -> dict[str, np.ndarray]:
    """The trees of a fitted binary ``model`` as padded (trees, nodes) arrays, plus its constant
    term (read off ``model.decision_function`` on ``X``)."""
    trees = [estimator.tree_ for estimator in model.estimators_[:, 0]]
    nodes = max(t.node_count for t in trees)
    arrays = {name: np.zeros((len(trees), nodes), dtype=dtype) for name, dtype in
              (("feature", np.int32), ("threshold", np.float64), ("left", np.int32), ("right", np.int32),
               ("value", np.float64))}
    for k, t in enumerate(trees):
        n = t.node_count
        arrays["feature"][k, :n] = np.maximum(t.feature, 0)
        arrays["threshold"][k, :n] = t.threshold
        arrays["left"][k, :n], arrays["left"][k, n:] = t.children_left, LEAF
        arrays["right"][k, :n], arrays["right"][k, n:] = t.children_right, LEAF
        arrays["value"][k, :n] = t.value[:, 0, 0]
    arrays["value"] *= model.learning_rate
    arrays["depth"] = np.array(max(e.get_depth() for e in model.estimators_[:, 0]))
    sample = X[:1]
    arrays["offset"] = np.array(float(model.decision_function(sample)[0]) - float(tree_sum(arrays, sample)[0]))
    return arrays


def tree_sum(arrays: dict[str, np.ndarray], X: np.ndarray) -> np.ndarray:
    """(n,) the summed leaf values of every tree for the rows of ``X`` (thresholds compared in
    float32, as scikit-learn's trees do), plus the constant term where present."""
    X32 = np.asarray(X, dtype=np.float32)
    feature, threshold, left, right = arrays["feature"], arrays["threshold"], arrays["left"], arrays["right"]
    trees = np.arange(len(feature))[None, :]
    rows = np.arange(len(X32))[:, None]
    node = np.zeros((len(X32), len(feature)), dtype=np.int32)
    for _ in range(int(arrays["depth"])):
        go_left = X32[rows, feature[trees, node]] <= threshold[trees, node]
        child = np.where(go_left, left[trees, node], right[trees, node])
        node = np.where(child == LEAF, node, child)
    return arrays["value"][trees, node].sum(axis=1) + float(arrays.get("offset", 0.0))
