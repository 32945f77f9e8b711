"""Top-down picture of a scene as seen from the start: the page's up is world +x, left is world +y."""

from __future__ import annotations

import math
import os

from matplotlib.axes import Axes
from matplotlib.patches import Circle, Rectangle
from matplotlib.patches import Polygon as PolygonPatch

from hlp_drake.files.plotting import new_figure, save_png
from hlp_drake.scene.geometry import footprint
from hlp_drake.scene.model import Scene, SceneObject
from hlp_drake.scene.rows import find_rows

ROW_COLOURS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#9467bd", "#8c564b", "#e377c2")


def page_xy(x: float, y: float) -> tuple[float, float]:
    """World (x, y) -> page (horizontal, vertical): horizontal = -y (left on the left), vertical = x."""
    return (-y, x)


def _draw_object(axes: Axes, obj: SceneObject, colour: str, label: str | None) -> None:
    if obj.shape == "cylinder":
        patch = Circle(page_xy(obj.x, obj.y), obj.size[0] / 2.0)
    else:
        corners = list(footprint(obj).exterior.coords)[:-1]
        patch = PolygonPatch([page_xy(x, y) for x, y in corners], closed=True)
    patch.set(facecolor=colour, edgecolor="black", linewidth=0.8, alpha=0.85)
    axes.add_patch(patch)
    if label:
        px, py = page_xy(obj.x, obj.y)
        axes.annotate(label, (px, py), ha="center", va="center", fontsize=6)


def draw_scene(axes: Axes, scene: Scene, *, labels: bool = True) -> None:
    """Draw table, rows, obstacles (coloured by row), start and target onto ``axes``."""
    table = scene.table
    axes.add_patch(
        Rectangle(
            (-table.width / 2.0, 0.0), table.width, table.length, facecolor="#f3ead8", edgecolor="#8b6d3f"
        )
    )
    row_of = {}
    for row in find_rows(scene):
        colour = ROW_COLOURS[(row.index - 1) % len(ROW_COLOURS)]
        axes.add_patch(
            Rectangle(
                (-table.width / 2.0, row.x_min),
                table.width,
                row.x_max - row.x_min,
                color=colour,
                alpha=0.12,
                zorder=0.5,
            )
        )
        axes.annotate(
            f"row {row.index}",
            (table.width / 2.0, row.x),
            xytext=(4, 0),
            textcoords="offset points",
            va="center",
            fontsize=8,
            color=colour,
        )
        row_of.update({name: colour for name in row.members})
    for obstacle in scene.obstacles:
        short = obstacle.name.replace("FailOnTouchObstacle", "")
        _draw_object(axes, obstacle, row_of.get(obstacle.name, "grey"), short if labels else None)
    _draw_object(axes, scene.target, "#d62728", "target" if labels else None)
    sx, sy = page_xy(*scene.start)
    axes.plot([sx], [sy], marker="o", color="black", markersize=7, zorder=5)
    arrow = 0.06
    dx, dy = page_xy(math.cos(scene.start_yaw) * arrow, math.sin(scene.start_yaw) * arrow)
    axes.annotate("", xy=(sx + dx, sy + dy), xytext=(sx, sy), arrowprops={"arrowstyle": "->"})
    axes.annotate("start", (sx, sy), xytext=(6, -10), textcoords="offset points", fontsize=8)
    margin = 0.05
    axes.set_xlim(-table.width / 2.0 - margin, table.width / 2.0 + margin + 0.08)
    axes.set_ylim(-margin, table.length + margin)
    axes.set_aspect("equal")
    axes.set_xlabel("lateral: -y (m), left of the start on the left")
    axes.set_ylabel("depth: x (m), away from the start")


PLAN_STYLES = (
    {"color": "#555555", "linestyle": "--", "marker": "o", "markersize": 4},
    {"color": "#1f5fd0", "linestyle": "-", "marker": "s", "markersize": 4},
)


def draw_plan(axes: Axes, plan, label: str, style: dict) -> None:
    """A plan's keypoints as a path from the start to the target, each keypoint marked (lifted ones hollow)."""
    if not plan.keypoints:
        return
    xs, ys = zip(*(page_xy(*k.position) for k in plan.keypoints))
    axes.plot(xs, ys, label=label, zorder=6, linewidth=1.5, **style)
    lifted = [page_xy(*k.position) for k in plan.keypoints if k.height is not None]
    if lifted:
        axes.plot(
            *zip(*lifted),
            linestyle="none",
            marker="o",
            markersize=9,
            markerfacecolor="none",
            color=style["color"],
            zorder=6,
        )


def save_scene_png(scene: Scene, path: str | os.PathLike[str], *, plans: dict | None = None) -> None:
    """Write a top-down PNG of ``scene`` to ``path``, with ``plans`` (label -> ``HighLevelPlan``) drawn over it."""
    figure, axes = new_figure()
    draw_scene(axes, scene)
    for (label, plan), style in zip((plans or {}).items(), PLAN_STYLES * 4):
        draw_plan(axes, plan, label, style)
    if plans:
        axes.legend(loc="lower left", fontsize=7)
    axes.set_title(scene.name or "scene")
    save_png(figure, path)
