"""Shared matplotlib set-up: a headless backend and atomic PNG output."""

from __future__ import annotations

import os

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
from matplotlib.figure import Figure

from hlp_drake.files.atomic import atomic_path


def save_png(figure: Figure, path: str | os.PathLike[str], *, dpi: int = 150) -> None:
    """Write ``figure`` to ``path`` as PNG atomically and close it."""
    try:
        with atomic_path(path) as tmp:
            figure.savefig(tmp, format="png", dpi=dpi, bbox_inches="tight")
    finally:
        plt.close(figure)


def new_figure(width: float = 6.0, height: float = 6.0) -> tuple[Figure, plt.Axes]:
    figure, axes = plt.subplots(figsize=(width, height))
    return figure, axes
