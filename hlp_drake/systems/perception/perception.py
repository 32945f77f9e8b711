"""What ``ScenePerception`` makes of a frame: ``perceive(views, config, template) -> Perception``.

Per frame: every pixel with a depth becomes a world point (the robot's pixels, by the label image,
are left out); the table is the largest horizontal plane (RANSAC, ``depth_points``); points
``min_height`` above it and over it are clustered in plan view; each cluster becomes an upright
box with a yaw or an upright cylinder fitted to its silhouette (``object_fit``), as tall as its top
above the plane. The
target is the cluster most of whose pixels the label image calls the target (a cylinder); the rest
are obstacles, named ``object_1``, ``object_2``, ... in order of x, then y. The start, the start
heading and the scene's name are the robot's own (the template's); nothing else of the template
is used.

A frame that cannot be read gives a ``Perception`` with a ``reason`` ("no table plane found",
"object at the image border (0.41, -0.52)", ...) and on ``scene`` a scene without a target, which
every planner refuses; it never raises inside the diagram.
"""

from __future__ import annotations

import functools
import time
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from hlp_drake.planner.blas import single_blas_thread
from hlp_drake.scene.geometry import footprint_bounds
from hlp_drake.scene.model import Scene, SceneObject, Table, plan_view_order
from hlp_drake.scene.validation import scene_problems
from hlp_drake.systems.perception.cameras import ROBOT_LABEL, TARGET_LABEL
from hlp_drake.systems.perception.depth_points import (
    CameraView,
    TablePlane,
    fit_table,
    pixel_points,
    valid_depth,
    view_points,
)
from hlp_drake.systems.perception.object_fit import (
    Cluster,
    boundaries,
    cluster_points,
    fit_object,
    linked_sample,
)

if TYPE_CHECKING:
    from hlp_drake.systems.perception.cameras import PerceptionConfig


@dataclass(frozen=True)
class PerceivedObject:
    """One object as perceived.

    Attributes:
        name, shape, x, y, yaw, size: as in ``SceneObject``.
        points: how many points it had.
        occluded: the share of its outline's pixels that something nearer hid.
        residual: RMS distance of its silhouette from the fitted outline, m.
        target_share: the share of its pixels the label image calls the target.
    """

    name: str
    shape: str
    x: float
    y: float
    yaw: float
    size: tuple[float, float, float]
    points: int
    occluded: float
    residual: float
    target_share: float

    def scene_object(self) -> SceneObject:
        return SceneObject(self.name, self.shape, self.x, self.y, self.size, self.yaw)


@dataclass(frozen=True)
class Perception:
    """What ``ScenePerception`` made of one frame.

    Attributes:
        scene: the perceived scene; when ``reason`` says why there is none, the template's table and
            start without objects (``unperceived_scene``), which every planner refuses.
        reason: why the frame gave no scene (None when it did).
        objects: the objects found (the target first).
        table: the fitted table plane (None if none was found).
        pixels: the frames' pixels; ``no_depth_pixels`` of them had no depth (NaN, too near, or
            too far: nothing there), ``nan_pixels`` of them NaN (no return: dropout).
        noise_points: points above the table in no object's cluster.
        perception_s: the time this took, s (the rendering not included).
        views: the frames perceived.
        class_images: per view (h, w), each pixel's class for display: 0 table, 1 object, 2 above
            the table but in no object, 3 anything else (``cloud`` and ``cloud_class``).
    """

    scene: Scene | None
    reason: str | None = None
    objects: tuple[PerceivedObject, ...] = ()
    table: TablePlane | None = None
    pixels: int = 0
    no_depth_pixels: int = 0
    nan_pixels: int = 0
    noise_points: int = 0
    perception_s: float = 0.0
    views: tuple[CameraView, ...] = field(default=(), compare=False, repr=False)
    class_images: tuple[np.ndarray, ...] = field(default=(), compare=False, repr=False)

    @functools.cached_property
    def _cloud(self) -> tuple[np.ndarray, np.ndarray]:
        points, _ = view_points(list(self.views))
        if not self.class_images:
            return points.xyz, np.full(len(points), 3)
        images = np.stack(self.class_images) if len(self.class_images) > 1 else self.class_images[0][None]
        return points.xyz, images[points.camera, points.row, points.col].astype(int)

    @property
    def cloud(self) -> np.ndarray:
        """Every pixel with a depth as a world point (n, 3), made when first asked (for display)."""
        return self._cloud[0]

    @property
    def cloud_class(self) -> np.ndarray:
        """The class of each of ``cloud``'s points (``class_images``)."""
        return self._cloud[1]

    @property
    def ok(self) -> bool:
        return self.reason is None and self.scene is not None

    def to_dict(self) -> dict[str, Any]:
        table = None
        if self.table is not None:
            table = {"plane": list(self.table.coefficients), "bounds": list(self.table.bounds)}
        return {
            "ok": self.ok,
            "reason": self.reason,
            "perceived": [
                {
                    "name": o.name,
                    "shape": o.shape,
                    "x": o.x,
                    "y": o.y,
                    "yaw": o.yaw,
                    "size": list(o.size),
                    "points": o.points,
                    "occluded": o.occluded,
                }
                for o in self.objects
            ],
            "table": table,
            "pixels": self.pixels,
            "no_depth_pixels": self.no_depth_pixels,
            "nan_pixels": self.nan_pixels,
            "perception_s": self.perception_s,
        }


def unperceived_scene(template: Scene) -> Scene:
    """The scene a failed frame gives: the template's table and start, no objects and no target."""
    return replace(template, target=None, obstacles=())


def _inside_table(obj: SceneObject, table: Table) -> SceneObject:
    """``obj`` moved the least to put its footprint on ``table`` (fitting can poke it past an edge)."""
    x0, y0, x1, y1 = footprint_bounds(obj)
    dx = max(0.0, -x0) - max(0.0, x1 - table.length)
    half = table.width / 2.0
    dy = max(0.0, -half - y0) - max(0.0, y1 - half)
    return obj if dx == dy == 0.0 else obj.moved(obj.x + dx, obj.y + dy)


def perceive(views: list[CameraView], config: PerceptionConfig, template: Scene) -> Perception:
    """The scene in ``views`` (see the module's docstring); the start and name are ``template``'s."""
    with single_blas_thread():  # small products: more BLAS threads only wait on a busy machine
        return _perceive(views, config, template, time.perf_counter())


def _perceive(
    views: list[CameraView], config: PerceptionConfig, template: Scene, started: float
) -> Perception:
    valid = [valid_depth(v.depth) for v in views]
    base = {
        "pixels": sum(v.depth.size for v in views),
        "no_depth_pixels": sum(int(m.size - m.sum()) for m in valid),
        "nan_pixels": sum(int(np.isnan(v.depth).sum()) for v in views),
        "views": tuple(views),
    }

    def failed(reason: str, **more: Any) -> Perception:
        elapsed = time.perf_counter() - started
        return Perception(unperceived_scene(template), reason, perception_s=elapsed, **base, **more)

    keep = [m & (v.labels != ROBOT_LABEL) for m, v in zip(valid, views)]
    table = fit_table(
        views,
        keep,
        tolerance=config.table_tolerance,
        sample=config.ransac_points,
        seed=config.seed,
        margin=config.table_margin,
    )
    if isinstance(table, str):
        return failed(table)
    x0, y0, x1, y1 = table.bounds
    heights = table.heights
    with np.errstate(invalid="ignore"):
        high = pixel_points(views, [k & (h >= config.min_height) for k, h in zip(keep, heights)])
    x, y = high.xyz[:, 0], high.xyz[:, 1]
    object_points = high.subset((x >= x0) & (x <= x1) & (y >= y0) & (y <= y1))
    radius = max(config.cluster_radius, 1.5 * table.pixel)
    linked = linked_sample(views, object_points, radius)
    groups = cluster_points(object_points, radius=radius, min_points=config.min_points, linked=linked)
    clusters = boundaries(views, object_points, groups, config.border_margin, table)
    clustered = np.zeros(len(object_points), bool)
    clustered[np.concatenate(groups) if groups else []] = True
    classes = _class_images(keep, heights, object_points, clustered, config.table_tolerance)
    noise = len(object_points) - int(clustered.sum())
    display = {"class_images": tuple(classes), "noise_points": noise, "table": table}
    for cluster in clusters:
        if _cut_off(cluster):
            cx, cy = cluster.points.xyz[:, :2].mean(axis=0)
            return failed(f"object at the image border ({cx:.2f}, {cy:.2f})", **display)
    if table.unseen_edges:
        edges = " and ".join(table.unseen_edges)
        return failed(f"the table reaches out of the cameras' view ({edges} edge)", **display)
    if not clusters:
        return failed("no target found (nothing stands on the table)", **display)
    shares = [float(np.mean(c.points.label == TARGET_LABEL)) for c in clusters]
    target = int(np.argmax(shares))
    if shares[target] < 0.5:
        return failed("no target found (no object is labelled the target)", **display)

    objects = [
        _perceived(cluster, table, views, share, template.target.name if i == target else "", i == target)
        for i, (cluster, share) in enumerate(zip(clusters, shares))
    ]
    others = plan_view_order(o for i, o in enumerate(objects) if i != target)
    objects = [objects[target], *(replace(o, name=f"object_{k}") for k, o in enumerate(others, start=1))]
    scene = _perceived_scene(template, table, objects)
    problems = scene_problems(scene)
    elapsed = time.perf_counter() - started
    result = Perception(scene, None, tuple(objects), perception_s=elapsed, **base, **display)
    if problems:
        return replace(
            result, scene=unperceived_scene(template), reason="perceived scene: " + "; ".join(problems)
        )
    return result


def _class_images(
    keep: list[np.ndarray], heights: list[np.ndarray], points, clustered: np.ndarray, tolerance: float
) -> list[np.ndarray]:
    """Each camera's class per pixel for display (``Perception.cloud_class``): 0 the table, 1 a
    clustered object point, 2 an object point in no cluster, 3 anything else."""
    classes = []
    for k, (mask, h) in enumerate(zip(keep, heights)):
        image = np.full(mask.shape, 3, dtype=np.int8)
        with np.errstate(invalid="ignore"):
            image[mask & (np.abs(h) <= tolerance)] = 0
        mine = points.camera == k
        image[points.row[mine], points.col[mine]] = 2
        mine &= clustered
        image[points.row[mine], points.col[mine]] = 1
        classes.append(image)
    return classes


def _perceived_scene(template: Scene, table: TablePlane, objects: list[PerceivedObject]) -> Scene:
    """``template`` with the perceived table and objects (the target first), each moved onto the table."""
    _, y0, x1, y1 = table.bounds
    perceived_table = Table(length=x1, width=y1 - y0, height=table.height_at(x1 / 2.0, (y0 + y1) / 2.0))
    placed = [_inside_table(o.scene_object(), perceived_table) for o in objects]
    return replace(template, table=perceived_table, target=placed[0], obstacles=tuple(placed[1:]))


def _perceived(
    cluster: Cluster, table: TablePlane, views: list[CameraView], share: float, name: str, target: bool
) -> PerceivedObject:
    """The object of ``cluster`` (a cylinder if it is the ``target``), seen mostly by one camera."""
    view = views[int(np.bincount(cluster.points.camera).argmax())]
    pixel = float(view.ground_sample(np.median(cluster.points.depth)))
    fit = fit_object(
        cluster, table.height_above(cluster.points.xyz), pixel, cylinder=True if target else None
    )
    outline = int(cluster.silhouette.sum() + cluster.occluded.sum())
    occluded = float(cluster.occluded.sum() / outline) if outline else 0.0
    return PerceivedObject(
        name, fit.shape, fit.x, fit.y, fit.yaw, fit.size, len(cluster.points), occluded, fit.residual, share
    )


def _cut_off(cluster: Cluster) -> bool:
    """Whether every camera that sees the cluster sees it reach its image's border."""
    cameras = np.unique(cluster.points.camera)
    return all(cluster.at_border[cluster.points.camera == k].any() for k in cameras)


__all__ = ["PerceivedObject", "Perception", "perceive", "unperceived_scene"]
