"""The default decision models shipped inside the package (trained on all 24 subjects)."""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path

from hlp_drake.learners.models import DecisionModels

BUNDLED_DIRECTORY = Path(__file__).resolve().parent.parent / "bundled_models"


@lru_cache(maxsize=1)
def default_models() -> DecisionModels:
    """Load the bundled models (``python -m hlp_drake.train --out`` reproduces them)."""
    return DecisionModels.load(BUNDLED_DIRECTORY)
