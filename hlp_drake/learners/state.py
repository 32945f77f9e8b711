"""The arrays a learner saves, declared by the learner: each array's dtype and shape in terms of the
learner's own dimensions (e.g. an SVM's ``support_vectors``: ``(n_support, n_features)``).

A dimension is a number (a fixed size) or a name, which every array of the learner that uses it must
share; ``model_format`` binds the names the feature code fixes (``n_features`` of each learner) and
checks every stored array against its learner's declaration before use.
"""

from __future__ import annotations

Spec = tuple[str, tuple[int | str, ...]]
"""An array's declaration: its dtype and its shape (sizes and dimension names)."""


def prefixed(prefix: str, state: dict[str, Spec]) -> dict[str, Spec]:
    """``state`` as a composite learner stores it under ``prefix`` (e.g. ``"gap."``): the arrays'
    names and the dimension names prefixed, so each learner's dimensions stay its own."""
    return {
        f"{prefix}{name}": (dtype, tuple(d if isinstance(d, int) else f"{prefix}{d}" for d in dims))
        for name, (dtype, dims) in state.items()
    }
