"""The picture a person checks a segmentation with: scene, hand path, gaps, decisions and keypoints."""

from __future__ import annotations

import os

from matplotlib.patches import Rectangle

from hlp_drake.files.plotting import new_figure, save_png
from hlp_drake.scene.plot import draw_scene, page_xy
from hlp_drake.segmentation.demonstration import OBJECT, Demonstration
from hlp_drake.taskspace import DIRECTION_VECTORS, TaskSpace

KEYPOINT_COLOURS = {
    "start": "black",
    "gap": "#2ca02c",
    "approach": "#d62728",
    "release": "#9467bd",
    "target": "#ff7f0e",
}


def save_segmentation_png(demo: Demonstration, path: str | os.PathLike[str]) -> None:
    """Write a top-down PNG of ``demo``: what was decided at each row and where the keypoints are."""
    figure, axes = new_figure(7.0, 7.0)
    draw_scene(axes, demo.scene)
    space = TaskSpace(demo.scene)
    for gaps, flags in zip(space.gaps, demo.gap_flags):
        for gap, passed in zip(gaps, flags):
            r = gap.rect
            axes.add_patch(
                Rectangle(
                    page_xy(r.x_min, r.y_max),
                    r.width,
                    r.depth,
                    fill=False,
                    linestyle="--",
                    edgecolor="#2ca02c" if passed else "#999999",
                    linewidth=1.2 if passed else 0.6,
                )
            )
            axes.annotate(
                f"g{gap.index}",
                page_xy(r.x_min, (r.y_min + r.y_max) / 2),
                xytext=(0, -8),
                textcoords="offset points",
                ha="center",
                fontsize=6,
                color="#555555",
            )
    path_xy = [page_xy(x, y) for x, y in demo.hand_path]
    axes.plot(*zip(*path_xy), color="#1f77b4", linewidth=1.0, label="hand (go part)")
    for decision in demo.decisions:
        if decision.decision == OBJECT:
            rect = space.rects[decision.obstacle]
            dx, dy = DIRECTION_VECTORS[decision.direction]
            (cx, cy), length = rect.center, 0.06
            axes.annotate(
                "",
                xy=page_xy(cx + dx * length, cy + dy * length),
                xytext=page_xy(cx, cy),
                arrowprops={"arrowstyle": "-|>", "color": "#d62728", "linewidth": 1.5},
            )
    for k, keypoint in enumerate(demo.keypoints):
        px, py = page_xy(*keypoint.position)
        axes.plot([px], [py], marker="o", markersize=6, color=KEYPOINT_COLOURS[keypoint.kind], zorder=6)
        axes.annotate(
            f"{k}:{keypoint.kind}",
            (px, py),
            xytext=(5, 4),
            textcoords="offset points",
            fontsize=7,
            color=KEYPOINT_COLOURS[keypoint.kind],
        )
    summary = "; ".join(
        f"row {d.row}: "
        + (
            f"moved {d.obstacle.replace('FailOnTouchObstacle', '')} {d.direction}"
            if d.decision == OBJECT
            else f"gap {d.gap}"
        )
        for d in demo.decisions
    )
    axes.set_title(f"{demo.key} ({demo.mode}): {summary}", fontsize=9)
    axes.legend(loc="lower left", fontsize=7)
    save_png(figure, path)
