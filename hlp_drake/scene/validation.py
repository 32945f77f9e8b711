"""Scene validation: one clear message per problem, at a cost of O(n log n) in the object count.

The limits (``TABLE_RANGE``, ``SIZE_RANGE``, ``MAX_OBSTACLES``, ``YAW_LIMIT``, ``MAX_NAME``) keep
every number the planner and Drake see physically sane; overlaps are found with a shapely
``STRtree`` and listed up to ``MAX_PROBLEMS`` pairs.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from numbers import Real

import numpy as np
import shapely

from hlp_drake.errors import MAX_PROBLEMS, SceneError
from hlp_drake.files.documents import brief
from hlp_drake.scene.geometry import footprint_bounds, footprints
from hlp_drake.scene.lazy import LazyRows
from hlp_drake.scene.model import SHAPES, Scene, SceneObject, Table

LENGTH_TOLERANCE = 1e-9  # m: how far a footprint may poke past the table edge (float noise)
AREA_TOLERANCE = 1e-9  # m^2: overlap area below which two objects only touch
TABLE_RANGE = (0.2, 5.0)
"""m: the table's length, width and height each lie in this range."""
SIZE_RANGE = (0.005, 1.0)
"""m: every size of an object (its two footprint extents and its height) lies in this range."""
MAX_OBSTACLES = 10_000
"""Most obstacles a scene may have."""
YAW_LIMIT = 2.0 * math.pi + 1e-9
"""rad: largest magnitude of an object's yaw or the start's heading."""
MAX_NAME = 100
"""Longest object or scene name, characters."""
_PAIRS_PER_BATCH = 4096  # candidate pairs whose overlap areas are computed at a time


def _is_finite(value: object) -> bool:
    if type(value) is float:  # the common case, without the abstract-class check
        return math.isfinite(value)
    try:
        return isinstance(value, Real) and not isinstance(value, bool) and math.isfinite(value)
    except OverflowError:  # an integer beyond a float's range
        return False


def _numbers(value: object, count: int) -> bool:
    """Whether ``value`` is a list, tuple or array of ``count`` finite numbers."""
    if not isinstance(value, tuple | list | np.ndarray) or len(value) != count:
        return False
    if isinstance(value, np.ndarray) and value.ndim != 1:
        return False
    return all(map(_is_finite, value))


def name_problem(name: object, limit: int = MAX_NAME) -> str | None:
    """Why ``name`` cannot name an object (or a camera), or None."""
    if not isinstance(name, str):
        return f"name must be text, got {brief(name)}"
    if len(name) > limit:
        return f"name is longer than {limit} characters ({brief(name)})"
    if not name.isprintable():
        return f"name has control characters ({brief(name)})"
    return None


def _label(obj: SceneObject, role: str) -> str:
    return f"{role} {obj.name!r}"


def _in_range(value: float, limits: tuple[float, float]) -> bool:
    return limits[0] <= value <= limits[1]


def _object_problems(obj: object, role: str, index: int) -> list[str]:
    """What is wrong with one object on its own (its placement is checked with the others)."""
    if not isinstance(obj, SceneObject):
        return [f"{role} {index}: expected a SceneObject, got {brief(obj)}"]
    named = name_problem(obj.name, MAX_NAME)
    if named is not None:
        return [f"{role} {index}: {named}"]
    if not obj.name:
        return [f"a {role} has no name"]
    problems = []
    if not isinstance(obj.shape, str) or obj.shape not in SHAPES:
        problems.append(f"unknown shape {brief(obj.shape)} (expected one of {', '.join(SHAPES)})")
    for attr, value in (("x", obj.x), ("y", obj.y), ("yaw", obj.yaw)):
        if not _is_finite(value):
            problems.append(f"{attr} must be a finite number, got {brief(value)}")
    if _is_finite(obj.yaw) and abs(obj.yaw) > YAW_LIMIT:
        problems.append(f"yaw must be within +-2 pi rad, got {obj.yaw!r}")
    size = obj.size
    if not _numbers(size, 3):
        problems.append(f"size must be 3 finite numbers, got {brief(size)}")
    elif min(size) <= 0.0:
        problems.append(f"size must be positive, got {list(size)!r}")
    elif not all(_in_range(v, SIZE_RANGE) for v in size):
        problems.append(f"sizes must be between {SIZE_RANGE[0]} and {SIZE_RANGE[1]} m, got {list(size)!r}")
    elif obj.shape == "cylinder" and not math.isclose(size[0], size[1], rel_tol=1e-6, abs_tol=1e-9):
        problems.append(
            "a cylinder's first two sizes are its diameter and must be equal, "
            f"got {size[0]!r} and {size[1]!r}"
        )
    return [f"{_label(obj, role)}: {problem}" for problem in problems]


def _plainly_sound(objects: Sequence[object]) -> np.ndarray:
    """(n,) which objects ``_object_problems`` would find nothing wrong with, for the common case
    checked in bulk (a SceneObject of plain floats, a known shape and a short printable name); the
    others (false here) go through ``_object_problems`` for their messages."""
    plain = [
        type(o) is SceneObject
        and type(o.name) is str
        and 0 < len(o.name) <= MAX_NAME
        and o.name.isprintable()
        and type(o.shape) is str
        and o.shape in SHAPES
        and type(o.x) is float
        and type(o.y) is float
        and type(o.yaw) is float
        and type(o.size) is tuple
        and len(o.size) == 3
        and all(type(v) is float for v in o.size)
        for o in objects
    ]
    sound = np.array(plain, dtype=bool)
    if not sound.any():
        return sound
    chosen = [o for o, p in zip(objects, plain) if p]
    values = np.array([(o.x, o.y, o.yaw, *o.size) for o in chosen], dtype=float)
    size = values[:, 3:]
    cylinder = np.array([o.shape == "cylinder" for o in chosen], dtype=bool)
    ok = np.isfinite(values).all(axis=1) & (np.abs(values[:, 2]) <= YAW_LIMIT)
    ok &= ((size >= SIZE_RANGE[0]) & (size <= SIZE_RANGE[1])).all(axis=1)
    diameters_equal = np.abs(size[:, 0] - size[:, 1]) <= np.maximum(
        1e-6 * np.maximum(np.abs(size[:, 0]), np.abs(size[:, 1])), 1e-9
    )  # math.isclose(rel_tol=1e-6, abs_tol=1e-9)
    ok &= ~cylinder | diameters_equal
    sound[np.flatnonzero(sound)] = ok
    return sound


def _off_table(obj: SceneObject, role: str, bounds: Sequence[float], table: Table) -> str:
    """What sides of the table the footprint ``bounds`` pokes past."""
    x_min, y_min, x_max, y_max = bounds
    tx_min, ty_min, tx_max, ty_max = table.bounds
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
    return f"{_label(obj, role)} is off the table ({', '.join(sides)})"


def _scene_shape_problems(scene: Scene) -> list[str]:
    """The problems of the scene's own fields (table, start, heading, name, obstacle count)."""
    problems: list[str] = []
    table = scene.table
    if not isinstance(table, Table):
        problems.append(f"table: expected a Table, got {brief(table)}")
    else:
        for attr in ("length", "width", "height"):
            value = getattr(table, attr)
            if not _is_finite(value) or value <= 0.0:
                problems.append(f"table: {attr} must be a positive number, got {brief(value)}")
            elif not _in_range(value, TABLE_RANGE):
                problems.append(
                    f"table: {attr} must be between {TABLE_RANGE[0]} and {TABLE_RANGE[1]} m, got {value!r}"
                )
    if not _numbers(scene.start, 2):
        problems.append(f"start must be 2 finite numbers (x, y), got {brief(scene.start)}")
    if not _is_finite(scene.start_yaw):
        problems.append(f"start_yaw must be a finite number, got {brief(scene.start_yaw)}")
    elif abs(scene.start_yaw) > YAW_LIMIT:
        problems.append(f"start_yaw must be within +-2 pi rad, got {scene.start_yaw!r}")
    named = name_problem(scene.name, 2 * MAX_NAME)
    if named is not None:
        problems.append(f"scene {named}")
    if not isinstance(scene.obstacles, tuple | list):
        problems.append(f"obstacles must be a tuple of SceneObjects, got {brief(scene.obstacles)}")
    elif len(scene.obstacles) > MAX_OBSTACLES:
        problems.append(f"more than {MAX_OBSTACLES} obstacles ({len(scene.obstacles)})")
    return problems


def scene_problems(scene: Scene) -> list[str]:
    """Every problem of ``scene``, one message each; empty when the scene is valid. Any object
    passes (a non-Scene, wrong types, huge numbers): the answer is then its problems."""
    if not isinstance(scene, Scene):
        return [f"expected a Scene, got {brief(scene)}"]
    problems = _scene_shape_problems(scene)
    if any(p.startswith(("obstacles must", "more than")) for p in problems):
        return problems
    table_ok = not any(p.startswith("table:") for p in problems)
    start_ok = not any(p.startswith("start must") for p in problems)

    if scene.target is None:
        problems.append("scene has no target")
        roles: list[tuple[object, str]] = []
    else:
        roles = [(scene.target, "target")]
        if isinstance(scene.target, SceneObject) and scene.target.shape != "cylinder":
            problems.append(
                f"target {scene.target.name!r} must be a cylinder, got {brief(scene.target.shape)}"
            )
    roles += [(obstacle, "obstacle") for obstacle in scene.obstacles]

    seen: set[str] = set()
    sound: list[tuple[SceneObject, str]] = []
    plainly_sound = _plainly_sound([obj for obj, _ in roles]).tolist()
    for index, (obj, role) in enumerate(roles):
        own = [] if plainly_sound[index] else _object_problems(obj, role, index)
        if isinstance(obj, SceneObject) and isinstance(obj.name, str) and obj.name:
            if obj.name in seen:
                problems.append(f"two objects are named {obj.name!r}")
            seen.add(obj.name)
        if role == "target" and isinstance(obj, SceneObject):  # another shape: "must be a cylinder", above
            problems += [p for p in own if not p.startswith(f"{_label(obj, role)}: unknown shape")]
        else:
            problems += own
        if not own:
            sound.append((obj, role))

    objects = [obj for obj, _ in sound]
    boxes = np.array([footprint_bounds(obj) for obj in objects], dtype=float).reshape(-1, 4)
    if table_ok:
        table = scene.table
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
            problems.append(_off_table(*sound[k], boxes[k], table))
    # The footprints' bounding boxes find the candidates; a footprint is built only for an object
    # of a candidate pair, or one whose box holds the start.
    shapes = LazyRows(len(objects), lambda index: footprints([objects[k] for k in index]))
    envelopes = shapely.box(boxes[:, 0], boxes[:, 1], boxes[:, 2], boxes[:, 3])
    tree = shapely.STRtree(envelopes)
    problems += _overlaps(sound, envelopes, shapes, tree)
    if start_ok:
        point = shapely.Point(float(scene.start[0]), float(scene.start[1]))
        near = np.sort(tree.query(point))
        inside = near[shapely.within(point, shapes[near])].tolist() if len(near) else []
        problems += [f"start point lies inside {_label(*sound[k])}" for k in inside]
    return problems


def _overlaps(
    sound: list[tuple[SceneObject, str]], envelopes: np.ndarray, shapes: LazyRows, tree: shapely.STRtree
) -> list[str]:
    """A message per pair of footprints (``shapes``) sharing more than ``AREA_TOLERANCE``, in index
    order, among the pairs whose ``envelopes`` (the ``tree``'s) meet; after ``MAX_PROBLEMS - 1``
    pairs one line says more overlap (so a pile of n equal objects costs O(n))."""
    problems: list[str] = []
    first, chunk = 0, 1
    while first < len(envelopes):  # chunks of 1, 2, 4, ... 256 objects: a pile is found in the first
        a, b = tree.query(envelopes[first : first + chunk], predicate="intersects")
        a = a + first
        first, chunk = first + chunk, min(2 * chunk, 256)
        keep = a < b
        order = np.lexsort((b[keep], a[keep]))
        a, b = a[keep][order], b[keep][order]
        for start in range(0, len(a), _PAIRS_PER_BATCH):
            i, j = a[start : start + _PAIRS_PER_BATCH], b[start : start + _PAIRS_PER_BATCH]
            areas = shapely.area(shapely.intersection(shapes[i], shapes[j]))
            for k in np.flatnonzero(areas > AREA_TOLERANCE).tolist():
                if len(problems) == MAX_PROBLEMS - 1:  # with the line below: what an error shows
                    return [*problems, f"more objects overlap (the first {len(problems)} pairs are listed)"]
                (obj_a, role_a), (obj_b, role_b) = sound[i[k]], sound[j[k]]
                problems.append(
                    f"{_label(obj_a, role_a)} and {_label(obj_b, role_b)} overlap ({areas[k] * 1e4:.2f} cm^2)"
                )
    return problems


def validate_scene(scene: Scene) -> Scene:
    """Return ``scene`` unchanged if valid, else raise ``SceneError`` listing every problem."""
    problems = scene_problems(scene)
    if problems:
        raise SceneError(*problems)
    return scene
