"""The default decision models shipped inside the package (trained on all 24 subjects)."""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path

from hlp_drake.learners.models import DecisionModels

BUNDLED_DIRECTORY = Path(__file__).resolve().parent.parent / "bundled_models"
BUNDLED_SHA256 = "0b64139c82516cc4d230d046d82a500f8e3581c2f9245e51550663680b000929"
"""The SHA-256 of the bundled ``models.json``: the bundled models are pinned (it holds the arrays' digest)."""


@lru_cache(maxsize=1)
def default_models() -> DecisionModels:
    """Load the bundled models (``python -m hlp_drake.train --out`` reproduces them)."""
    return DecisionModels.load(BUNDLED_DIRECTORY, sha256=BUNDLED_SHA256)
