"""Scene validation: one clear message per problem."""

from __future__ import annotations

import math
from functools import cache
from numbers import Real

import numpy as np
import shapely

from hlp_drake.errors import SceneError
from hlp_drake.scene.geometry import footprint, footprint_bounds, overlapping_bounds
from hlp_drake.scene.model import SHAPES, Scene, SceneObject

LENGTH_TOLERANCE = 1e-9  # m: how far a footprint may poke past the table edge (float noise)
AREA_TOLERANCE = 1e-9  # m^2: overlap area below which two objects only touch
BOUNDS_MARGIN = 1e-6  # m: boxes this close may touch (footprints vs their float bounding boxes)


def _is_finite(value: object) -> bool:
    if type(value) is float:  # the common case, without the abstract-class check
        return math.isfinite(value)
    return isinstance(value, Real) and not isinstance(value, bool) and math.isfinite(value)


def _label(obj: SceneObject, role: str) -> str:
    return f"{role} {obj.name!r}"


def _object_problems(obj: SceneObject, role: str) -> list[str]:
    problems = []
    if obj.shape not in SHAPES:
        problems.append(f"unknown shape {obj.shape!r} (expected one of {', '.join(SHAPES)})")
    for attr, value in (("x", obj.x), ("y", obj.y), ("yaw", obj.yaw)):
        if not _is_finite(value):
            problems.append(f"{attr} must be a finite number, got {value!r}")
    size = obj.size
    if len(size) != 3 or not all(map(_is_finite, size)):
        problems.append(f"size must be 3 finite numbers, got {list(size)!r}")
    elif min(size) <= 0.0:
        problems.append(f"size must be positive, got {list(size)!r}")
    elif obj.shape == "cylinder" and not math.isclose(size[0], size[1], rel_tol=1e-6, abs_tol=1e-9):
        problems.append(
            "a cylinder's first two sizes are its diameter and must be equal, "
            f"got {size[0]!r} and {size[1]!r}"
        )
    return [f"{_label(obj, role)}: {problem}" for problem in problems]


def _off_table(obj: SceneObject, role: str, bounds: tuple[float, ...], scene: Scene) -> str | None:
    """What sides of the table the footprint ``bounds`` pokes past, if any."""
    x_min, y_min, x_max, y_max = bounds
    tx_min, ty_min, tx_max, ty_max = scene.table.bounds
    tol = LENGTH_TOLERANCE
    sides = []
    if x_min < tx_min - tol:
        sides.append(f"{tx_min - x_min:.3f} m past the front edge")
    if x_max > tx_max + tol:
        sides.append(f"{x_max - tx_max:.3f} m past the back edge")
    if y_min < ty_min - tol:
        sides.append(f"{ty_min - y_min:.3f} m past the right edge")
    if y_max > ty_max + tol:
        sides.append(f"{y_max - ty_max:.3f} m past the left edge")
    if not sides:
        return None
    return f"{_label(obj, role)} is off the table ({', '.join(sides)})"


def scene_problems(scene: Scene) -> list[str]:
    """Every problem of ``scene``, one message each; empty when the scene is valid."""
    problems: list[str] = []
    table = scene.table
    table_ok = True
    for attr in ("length", "width", "height"):
        value = getattr(table, attr)
        if not _is_finite(value) or value <= 0.0:
            problems.append(f"table: {attr} must be a positive number, got {value!r}")
            table_ok = False

    start_ok = len(scene.start) == 2 and all(_is_finite(v) for v in scene.start)
    if not start_ok:
        problems.append(f"start must be 2 finite numbers (x, y), got {list(scene.start)!r}")
    if not _is_finite(scene.start_yaw):
        problems.append(f"start_yaw must be a finite number, got {scene.start_yaw!r}")

    if scene.target is None:
        problems.append("scene has no target")
        roles: list[tuple[SceneObject, str]] = []
    else:
        roles = [(scene.target, "target")]
        if scene.target.shape != "cylinder":
            problems.append(f"target {scene.target.name!r} must be a cylinder, got {scene.target.shape!r}")
    roles += [(obstacle, "obstacle") for obstacle in scene.obstacles]

    seen: set[str] = set()
    sound: list[tuple[SceneObject, str]] = []
    for obj, role in roles:
        if not isinstance(obj.name, str) or not obj.name:
            problems.append(f"a {role} has no name")
        elif obj.name in seen:
            problems.append(f"two objects are named {obj.name!r}")
        seen.add(obj.name)
        own = _object_problems(obj, role)
        problems += own
        if not own:
            sound.append((obj, role))

    bounds = [footprint_bounds(obj) for obj, _ in sound]
    boxes = np.array(bounds, dtype=float).reshape(-1, 4)
    if table_ok:
        if start_ok:
            x, y = scene.start
            x_min, y_min, x_max, y_max = table.bounds
            tol = LENGTH_TOLERANCE
            if not (x_min - tol <= x <= x_max + tol and y_min - tol <= y <= y_max + tol):
                problems.append(f"start point ({x:.3f}, {y:.3f}) is off the table")
        edges = np.array(table.bounds)
        outside = np.any(boxes[:, :2] < edges[:2] - LENGTH_TOLERANCE, axis=1) | np.any(
            boxes[:, 2:] > edges[2:] + LENGTH_TOLERANCE, axis=1
        )
        for k in np.flatnonzero(outside).tolist():  # the message names the sides
            problems.append(_off_table(*sound[k], bounds[k], scene))
    problems += _overlaps(sound, boxes)
    if start_ok:
        problems += _start_inside(sound, bounds, scene.start)
    return problems


def _overlaps(sound: list[tuple[SceneObject, str]], bounds: np.ndarray) -> list[str]:
    """A message per pair of footprints sharing more than ``AREA_TOLERANCE`` (only pairs whose
    bounding boxes meet are intersected)."""
    problems = []
    pairs = overlapping_bounds(bounds, BOUNDS_MARGIN).tolist()
    shape = cache(lambda i: footprint(sound[i][0])) if pairs else None
    for i, j in pairs:
        (a, role_a), (b, role_b) = sound[i], sound[j]
        poly_a, poly_b = shape(i), shape(j)
        if not poly_a.intersects(poly_b):
            continue
        area = poly_a.intersection(poly_b).area
        if area > AREA_TOLERANCE:
            problems.append(f"{_label(a, role_a)} and {_label(b, role_b)} overlap ({area * 1e4:.2f} cm^2)")
    return problems


def _start_inside(
    sound: list[tuple[SceneObject, str]], bounds: list[tuple[float, ...]], start: tuple[float, float]
) -> list[str]:
    """A message per footprint the start point lies in (only footprints whose box holds it are tested)."""
    x, y = start
    m = BOUNDS_MARGIN
    near = [
        obj_role
        for obj_role, (x0, y0, x1, y1) in zip(sound, bounds)
        if x0 - m < x < x1 + m and y0 - m < y < y1 + m
    ]
    point = shapely.Point(x, y) if near else None
    return [
        f"start point lies inside {_label(obj, role)}" for obj, role in near if footprint(obj).contains(point)
    ]


def validate_scene(scene: Scene) -> Scene:
    """Return ``scene`` unchanged if valid, else raise ``SceneError`` listing every problem."""
    problems = scene_problems(scene)
    if problems:
        raise SceneError(*problems)
    return scene
