"""Per-obstacle tables filled on first use: a plan asks about a few obstacles of a large scene."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np


class LazyRows:
    """The rows of an (n, ...) table, each computed the first time it is asked for.

    ``rows[index]`` computes the rows of ``index`` not known yet in one call of ``compute`` (given
    their indices in increasing order, it returns their rows in that order) and returns the rows of
    ``index``: the same values as computing the whole table at once, for the rows a caller uses.
    """

    def __init__(self, n: int, compute: Callable[[np.ndarray], np.ndarray]) -> None:
        self._compute = compute
        self._known = np.zeros(n, dtype=bool)
        self._values: np.ndarray | None = None

    def __len__(self) -> int:
        return len(self._known)

    def __getitem__(self, index: int | np.ndarray) -> np.ndarray:
        index = np.asarray(index, dtype=int)
        known = self._known[index]
        if not known.all():
            missing = np.unique(index[~known])
            values = np.asarray(self._compute(missing))
            if self._values is None:
                self._values = np.empty((len(self._known), *values.shape[1:]), dtype=values.dtype)
            self._values[missing] = values
            self._known[missing] = True
        if self._values is None:  # nothing asked for yet, nor now
            return np.empty((*index.shape, 0))
        return self._values[index]
