"""Class balancing by oversampling (the original's 'INC' rule), done inside ``fit`` only."""

from __future__ import annotations

import numpy as np


def oversample(
    X: np.ndarray, y: np.ndarray, rng: np.random.Generator, max_per_class: int | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Bring every class to the size of the largest (whole copies plus a random remainder).

    Args:
        max_per_class: first subsample classes larger than this (keeps big sets fast to fit).
    """
    classes, counts = np.unique(y, return_counts=True)
    target = int(counts.max()) if max_per_class is None else min(int(counts.max()), max_per_class)
    rows = []
    for cls in classes:
        index = np.flatnonzero(y == cls)
        if len(index) >= target:
            rows.append(rng.choice(index, target, replace=False))
            continue
        copies, rest = divmod(target, len(index))
        rows.append(np.concatenate([np.tile(index, copies), rng.choice(index, rest, replace=False)]))
    order = np.concatenate(rows)
    return X[order], y[order]
