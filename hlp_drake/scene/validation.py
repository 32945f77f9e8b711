"""Scene validation: one clear message per problem."""

from __future__ import annotations

import math
from numbers import Real

import shapely

from hlp_drake.errors import SceneError
from hlp_drake.scene.geometry import footprint, footprint_bounds
from hlp_drake.scene.model import SHAPES, Scene, SceneObject

LENGTH_TOLERANCE = 1e-9  # m: how far a footprint may poke past the table edge (float noise)
AREA_TOLERANCE = 1e-9  # m^2: overlap area below which two objects only touch


def _is_finite(value: object) -> bool:
    return isinstance(value, Real) and not isinstance(value, bool) and math.isfinite(value)


def _label(obj: SceneObject, role: str) -> str:
    return f"{role} {obj.name!r}"


def _object_problems(obj: SceneObject, role: str) -> list[str]:
    label = _label(obj, role)
    problems = []
    if obj.shape not in SHAPES:
        problems.append(f"{label}: unknown shape {obj.shape!r} (expected one of {', '.join(SHAPES)})")
    for attr in ("x", "y", "yaw"):
        value = getattr(obj, attr)
        if not _is_finite(value):
            problems.append(f"{label}: {attr} must be a finite number, got {value!r}")
    size = obj.size
    if len(size) != 3 or not all(_is_finite(v) for v in size):
        problems.append(f"{label}: size must be 3 finite numbers, got {list(size)!r}")
    elif min(size) <= 0.0:
        problems.append(f"{label}: size must be positive, got {list(size)!r}")
    elif obj.shape == "cylinder" and not math.isclose(size[0], size[1], rel_tol=1e-6, abs_tol=1e-9):
        problems.append(
            f"{label}: a cylinder's first two sizes are its diameter and must be equal, "
            f"got {size[0]!r} and {size[1]!r}"
        )
    return problems


def _off_table(obj: SceneObject, role: str, scene: Scene) -> str | None:
    x_min, y_min, x_max, y_max = footprint_bounds(obj)
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

    if table_ok:
        if start_ok:
            x, y = scene.start
            x_min, y_min, x_max, y_max = table.bounds
            tol = LENGTH_TOLERANCE
            if not (x_min - tol <= x <= x_max + tol and y_min - tol <= y <= y_max + tol):
                problems.append(f"start point ({x:.3f}, {y:.3f}) is off the table")
        for obj, role in sound:
            message = _off_table(obj, role, scene)
            if message:
                problems.append(message)

    shapes = [(obj, role, footprint(obj)) for obj, role in sound]
    for i, (a, role_a, poly_a) in enumerate(shapes):
        for b, role_b, poly_b in shapes[i + 1 :]:
            if not poly_a.intersects(poly_b):
                continue
            area = poly_a.intersection(poly_b).area
            if area > AREA_TOLERANCE:
                problems.append(
                    f"{_label(a, role_a)} and {_label(b, role_b)} overlap ({area * 1e4:.2f} cm^2)"
                )
    if start_ok:
        start_point = shapely.Point(*scene.start)
        for obj, role, poly in shapes:
            if poly.contains(start_point):
                problems.append(f"start point lies inside {_label(obj, role)}")
    return problems


def validate_scene(scene: Scene) -> Scene:
    """Return ``scene`` unchanged if valid, else raise ``SceneError`` listing every problem."""
    problems = scene_problems(scene)
    if problems:
        raise SceneError(*problems)
    return scene
