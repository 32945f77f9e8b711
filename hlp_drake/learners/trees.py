"""Boosted decision trees as plain arrays: fitted by scikit-learn, evaluated here, saved as NPZ.

``GradientBoostingClassifier`` exposes its trees (``estimators_``, each ``tree_`` with its node
arrays); copying those arrays makes a fitted model a handful of numbers that load without pickle
and predict the same on any scikit-learn version.
"""

from __future__ import annotations

from typing import ClassVar

import numpy as np
from sklearn.ensemble import GradientBoostingClassifier

from hlp_drake.learners.state import Spec

LEAF = -1  # child index of a leaf (scikit-learn's TREE_LEAF)


def boosted_tree_arrays(model: GradientBoostingClassifier, X: np.ndarray) -> dict[str, np.ndarray]:
    """The trees of a fitted binary ``model`` as padded (trees, nodes) arrays, plus its constant
    term (read off ``model.decision_function`` on ``X``)."""
    trees = [estimator.tree_ for estimator in model.estimators_[:, 0]]
    nodes = max(t.node_count for t in trees)
    arrays = {
        name: np.zeros((len(trees), nodes), dtype=dtype)
        for name, dtype in (
            ("feature", np.int32),
            ("threshold", np.float64),
            ("left", np.int32),
            ("right", np.int32),
            ("value", np.float64),
        )
    }
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
    arrays["offset"] = np.array(0.0)
    arrays["offset"] = np.array(
        float(model.decision_function(sample)[0]) - float(BoostedTrees(arrays).decision_function(sample)[0])
    )
    return arrays


class BoostedTrees:
    """Evaluates the trees of ``boosted_tree_arrays``: the summed leaf values plus the constant.

    The nodes are laid out flat (node k of tree t at t * nodes + k), a leaf's children pointing at
    itself, so every row walks the full depth in a few array operations.
    """

    STATE: ClassVar[dict[str, Spec]] = {
        "feature": ("int32", ("n_trees", "n_nodes")),
        "threshold": ("float64", ("n_trees", "n_nodes")),
        "left": ("int32", ("n_trees", "n_nodes")),
        "right": ("int32", ("n_trees", "n_nodes")),
        "value": ("float64", ("n_trees", "n_nodes")),
        "depth": ("int64", ()),
        "offset": ("float64", ()),
    }
    """The arrays of ``boosted_tree_arrays``: dtype and shape."""

    def __init__(self, arrays: dict[str, np.ndarray]) -> None:
        self.arrays = arrays
        trees, nodes = arrays["feature"].shape
        ids = np.arange(trees * nodes).reshape(trees, nodes)
        leaf = arrays["left"] == LEAF
        base = (np.arange(trees) * nodes)[:, None]
        self._roots = base[:, 0]
        self._feature, self._threshold = arrays["feature"].ravel(), arrays["threshold"].ravel()
        self._left = np.where(leaf, ids, arrays["left"] + base).ravel()
        self._right = np.where(leaf, ids, arrays["right"] + base).ravel()
        self._value = arrays["value"].ravel()
        self._depth, self._offset = int(arrays["depth"]), float(arrays.get("offset", 0.0))

    def decision_function(self, X: np.ndarray) -> np.ndarray:
        """(n,) the trees' score of the rows of ``X`` (thresholds compared in float32, as
        scikit-learn's trees do)."""
        X32 = np.ascontiguousarray(X, dtype=np.float32)
        rows = (np.arange(len(X32)) * X32.shape[1])[:, None]
        values = X32.ravel()
        node = np.broadcast_to(self._roots, (len(X32), len(self._roots)))
        for _ in range(self._depth):
            go_left = values[rows + self._feature[node]] <= self._threshold[node]
            node = np.where(go_left, self._left[node], self._right[node])
        return self._value[node].sum(axis=1) + self._offset
