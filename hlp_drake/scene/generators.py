"""Seeded scene generators: the VR two-row structure, Generalization I and II, unstructured layouts.

Every generator is a pure function of its seed (``numpy.random.default_rng(seed)``). All scenes are in
the world frame of ``hlp_drake.dataset.frames`` (front edge of the table at x = 0, y to the left).

- ``vr``: the dataset's structured trials (T010-T099): the 0.74 x 0.60 m VR table, obstacle rows at
  0.245 and 0.405 m from the front edge, one short (0.05 m), medium (0.10) and long (0.15) obstacle per
  row in random order, free intervals of at least 5 mm on a 5 mm grid, target can at 0.525 m.
- ``gen1``: Generalization I: the same two-row structure on a robot-sized table with table and object
  dimensions varied (see ``GEN1``).
- ``gen2``: Generalization II: 5, 7 or 9 (any N >= 1) boxes and cylinders placed at random, the start
  on a random point of the front edge with a random heading, the target not aligned with the start.
- ``unstructured``: the dataset's unstructured trials (T100-T129): the VR table, N (default 6) obstacles
  at random on a 1 cm grid, random lateral start and target positions.

For a robot fixed before the table, gen1 and gen2 keep their tables within its reach (``workspace``);
``hlp_drake.scene.scaled`` scales a given scene (the bundled default) by the same factor.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace

import numpy as np
import shapely
from shapely.geometry import Polygon

from hlp_drake.config.ranges import MAX_SEED
from hlp_drake.errors import SceneError
from hlp_drake.files.documents import brief
from hlp_drake.scene.constants import KINDS, MAX_GENERATED
from hlp_drake.scene.geometry import footprint
from hlp_drake.scene.model import Scene, SceneObject, Table
from hlp_drake.scene.validation import validate_scene
from hlp_drake.scene.workspace import EDGE_INSET, Workspace, within_reach

# --- The VR study (reference notes 1.2): metres, world frame. -----------------------------------
VR_TABLE = Table(length=0.60, width=0.74, height=0.73)
VR_START = (0.10, 0.0)
VR_TARGET_X = 0.525
VR_TARGET_SIZE = (0.05, 0.05, 0.085)
VR_ROW_X = (0.245, 0.405)
VR_OBSTACLE_DEPTH = 0.05
VR_OBSTACLE_HEIGHT = 0.12
VR_OBSTACLE_WIDTHS = {"Short": 0.05, "Med": 0.10, "Long": 0.15}
VR_MIN_GAP = 0.005
VR_GRID = 0.005
VR_OBSTACLE_PREFIX = "FailOnTouchObstacle"


@dataclass(frozen=True)
class RobotSceneRanges:
    """Uniform ranges (low, high) of the robot-sized generalization scenes, metres / radians."""

    table_length: tuple[float, float] = (0.70, 1.00)
    table_width: tuple[float, float] = (0.90, 1.30)
    table_height: tuple[float, float] = (0.70, 0.80)
    object_scale_jitter: tuple[float, float] = (0.80, 1.25)  # Gen I: multiplies scaled VR sizes
    object_height: tuple[float, float] = (0.10, 0.20)
    target_diameter: tuple[float, float] = (0.05, 0.07)  # graspable by an 85 mm gripper
    target_height: tuple[float, float] = (0.10, 0.15)
    box_depth: tuple[float, float] = (0.05, 0.10)  # Gen II
    box_width: tuple[float, float] = (0.06, 0.22)
    cylinder_diameter: tuple[float, float] = (0.05, 0.10)
    start_yaw: tuple[float, float] = (-math.pi / 4, math.pi / 4)
    obstacle_band: tuple[float, float] = (0.20, 0.72)  # Gen II obstacle x, fraction of table length
    target_band: tuple[float, float] = (0.78, 0.90)  # Gen II target x, fraction of table length
    min_clearance: float = 0.01  # Gen II: between objects, m
    min_misalignment: float = 0.10  # Gen II: |target y - start y| >= this fraction of the width


GEN1 = RobotSceneRanges()
DECIMALS = 4  # generated values are rounded to 0.1 mm / 0.1 mrad so files read cleanly
MAX_PLACEMENT_ATTEMPTS = 2000


def _rounded(value: float) -> float:
    return round(float(value), DECIMALS)


def finished(scene: Scene) -> Scene:
    """Round every generated number to ``DECIMALS`` and validate the scene."""

    def tidy(obj: SceneObject) -> SceneObject:
        return replace(
            obj,
            x=_rounded(obj.x),
            y=_rounded(obj.y),
            yaw=_rounded(obj.yaw),
            size=tuple(_rounded(v) for v in obj.size),  # type: ignore[arg-type]
        )

    table = scene.table
    return validate_scene(
        replace(
            scene,
            table=Table(_rounded(table.length), _rounded(table.width), _rounded(table.height)),
            start=(_rounded(scene.start[0]), _rounded(scene.start[1])),
            start_yaw=_rounded(scene.start_yaw),
            target=tidy(scene.target),
            obstacles=tuple(tidy(o) for o in scene.obstacles),
        )
    )


def _uniform(rng: np.random.Generator, bounds: tuple[float, float]) -> float:
    return float(rng.uniform(bounds[0], bounds[1]))


def _split_free_space(
    rng: np.random.Generator, free: float, parts: int, min_gap: float, grid: float | None
) -> list[float]:
    """Split ``free`` metres into ``parts`` random intervals of at least ``min_gap`` each."""
    spare = free - parts * min_gap
    if spare < 0:
        raise SceneError(f"objects do not fit in the row: {free:.3f} m free for {parts} gaps")
    if grid is None:
        shares = rng.dirichlet(np.ones(parts)) * spare
    else:
        units = math.floor(spare / grid + 1e-9)
        cuts = np.sort(rng.choice(units + parts - 1, size=parts - 1, replace=False))
        counts = np.diff(np.concatenate(([-1], cuts, [units + parts - 1]))) - 1
        shares = counts * grid
        shares[-1] += spare - units * grid
    return [min_gap + float(s) for s in shares]


def _row_of_boxes(
    rng: np.random.Generator,
    *,
    table: Table,
    row_x: float,
    names: Sequence[str],
    widths: Sequence[float],
    depths: Sequence[float],
    heights: Sequence[float],
    min_gap: float,
    grid: float | None,
) -> list[SceneObject]:
    """Boxes in random left-to-right order across the table, centred on depth ``row_x``."""
    order = rng.permutation(len(names))
    gaps = _split_free_space(rng, table.width - float(np.sum(widths)), len(names) + 1, min_gap, grid)
    boxes = []
    y_edge = table.width / 2.0  # left edge (+y); walk to the right (-y)
    for gap, i in zip(gaps, order):
        y_edge -= gap
        y = y_edge - widths[i] / 2.0
        if grid is not None:
            y = round(y / (grid / 2.0)) * (grid / 2.0)  # lateral centres on the VR 2.5 mm grid
        boxes.append(
            SceneObject(
                name=names[i],
                shape="box",
                x=row_x,
                y=y,
                size=(float(depths[i]), float(widths[i]), float(heights[i])),
            )
        )
        y_edge -= widths[i]
    return sorted(boxes, key=lambda b: names.index(b.name))


def _vr_names(row: int) -> list[str]:
    suffix = "" if row == 0 else f"-{row}"
    return [f"{VR_OBSTACLE_PREFIX}{size}{suffix}" for size in VR_OBSTACLE_WIDTHS]


def generate_vr(seed: int) -> Scene:
    """A structured two-row scene as in the VR study's trials T010-T099."""
    rng = np.random.default_rng(seed)
    widths = list(VR_OBSTACLE_WIDTHS.values())
    obstacles: list[SceneObject] = []
    for row, row_x in enumerate(VR_ROW_X):
        obstacles += _row_of_boxes(
            rng,
            table=VR_TABLE,
            row_x=row_x,
            names=_vr_names(row),
            widths=widths,
            depths=[VR_OBSTACLE_DEPTH] * 3,
            heights=[VR_OBSTACLE_HEIGHT] * 3,
            min_gap=VR_MIN_GAP,
            grid=VR_GRID,
        )
    target = SceneObject(name="Target", shape="cylinder", x=VR_TARGET_X, y=0.0, size=VR_TARGET_SIZE)
    return finished(
        Scene(table=VR_TABLE, start=VR_START, target=target, obstacles=tuple(obstacles), name=f"vr-{seed}")
    )


def _robot_table(rng: np.random.Generator, ranges: RobotSceneRanges) -> Table:
    return Table(
        length=_uniform(rng, ranges.table_length),
        width=_uniform(rng, ranges.table_width),
        height=_uniform(rng, ranges.table_height),
    )


def _target(rng: np.random.Generator, ranges: RobotSceneRanges, x: float, y: float) -> SceneObject:
    diameter = _uniform(rng, ranges.target_diameter)
    return SceneObject(
        name="Target",
        shape="cylinder",
        x=x,
        y=y,
        size=(diameter, diameter, _uniform(rng, ranges.target_height)),
    )


def generate_gen1(seed: int, ranges: RobotSceneRanges = GEN1) -> Scene:
    """Generalization I: the VR two-row structure on a robot-sized table, dimensions varied.

    Depths (start, rows, target) keep their VR fractions of the table length; obstacle sizes are the
    VR sizes scaled by table width / 0.74, each jittered independently.
    """
    rng = np.random.default_rng(seed)
    table = _robot_table(rng, ranges)
    scale = table.width / VR_TABLE.width
    depth_ratio = table.length / VR_TABLE.length
    obstacles: list[SceneObject] = []
    for row, vr_x in enumerate(VR_ROW_X):
        jitter = rng.uniform(*ranges.object_scale_jitter, size=(2, 3))
        obstacles += _row_of_boxes(
            rng,
            table=table,
            row_x=vr_x * depth_ratio,
            names=_vr_names(row),
            widths=[w * scale * j for w, j in zip(VR_OBSTACLE_WIDTHS.values(), jitter[0])],
            depths=[VR_OBSTACLE_DEPTH * scale * j for j in jitter[1]],
            heights=rng.uniform(*ranges.object_height, size=3).tolist(),
            min_gap=VR_MIN_GAP * scale,
            grid=None,
        )
    target = _target(rng, ranges, VR_TARGET_X * depth_ratio, 0.0)
    start = (VR_START[0] * depth_ratio, 0.0)
    return finished(
        Scene(table=table, start=start, target=target, obstacles=tuple(obstacles), name=f"gen1-{seed}")
    )


def _place_at_random(
    rng: np.random.Generator,
    make: Callable[[], SceneObject],
    occupied: list[Polygon],
    clearance: float,
    what: str,
) -> SceneObject:
    """Draw objects from ``make`` until one keeps ``clearance`` from every occupied footprint."""
    for _ in range(MAX_PLACEMENT_ATTEMPTS):
        candidate = make()
        shape = footprint(candidate)
        if all(shape.distance(other) >= clearance for other in occupied):
            occupied.append(shape)
            return candidate
    raise SceneError(f"could not place {what} after {MAX_PLACEMENT_ATTEMPTS} attempts; use fewer objects")


def _keep_clear(point: tuple[float, float], radius: float) -> Polygon:
    """A disc around ``point`` that random placement must keep clear of (the start)."""
    return shapely.Point(*point).buffer(radius)


def _inset(rng: np.random.Generator, low: float, high: float, margin: float) -> float:
    """Uniform in [low, high] kept ``margin`` from both ends, plus two rounding units: rounding the
    position and the size to ``DECIMALS`` afterwards can then never push the object over an edge."""
    margin += 2 * 10.0**-DECIMALS
    return float(rng.uniform(low + margin, high - margin))


def generate_gen2(seed: int, objects: int = 7, ranges: RobotSceneRanges = GEN1) -> Scene:
    """Generalization II: ``objects`` random boxes and cylinders, start on the front edge."""
    if objects < 1:
        raise SceneError(f"gen2 needs at least 1 object, got {objects}")
    rng = np.random.default_rng(seed)
    table = _robot_table(rng, ranges)
    half = table.width / 2.0
    start = (0.0, _inset(rng, -half, half, EDGE_INSET))
    start_yaw = _uniform(rng, ranges.start_yaw)
    min_offset = ranges.min_misalignment * table.width
    while True:  # target y away from the start's line; terminates: the admissible set is non-empty
        target_y = _inset(rng, -half, half, EDGE_INSET)
        if abs(target_y - start[1]) >= min_offset:
            break
    band = [f * table.length for f in ranges.target_band]
    target = _target(rng, ranges, float(rng.uniform(*band)), target_y)
    occupied = [footprint(target), _keep_clear(start, 0.05)]
    x_band = [f * table.length for f in ranges.obstacle_band]

    def make(index: int) -> Callable[[], SceneObject]:
        def draw() -> SceneObject:
            height = _uniform(rng, ranges.object_height)
            if rng.random() < 0.5:
                d = _uniform(rng, ranges.cylinder_diameter)
                shape, size = "cylinder", (d, d, height)
            else:
                shape = "box"
                size = (_uniform(rng, ranges.box_depth), _uniform(rng, ranges.box_width), height)
            margin = max(size[0], size[1]) / 2.0
            return SceneObject(
                name=f"obstacle_{index}",
                shape=shape,
                x=float(rng.uniform(*x_band)),
                y=_inset(rng, -half, half, margin),
                size=size,
            )

        return draw

    obstacles = tuple(
        _place_at_random(rng, make(i), occupied, ranges.min_clearance, f"obstacle {i} of {objects}")
        for i in range(1, objects + 1)
    )
    return finished(
        Scene(
            table=table,
            start=start,
            target=target,
            obstacles=obstacles,
            start_yaw=start_yaw,
            name=f"gen2-{objects}-{seed}",
        )
    )


def generate_unstructured(seed: int, objects: int = 6) -> Scene:
    """An unstructured VR layout as in trials T100-T129: obstacles anywhere between start and target."""
    if objects < 1:
        raise SceneError(f"unstructured needs at least 1 object, got {objects}")
    rng = np.random.default_rng(seed)
    cm = 0.01
    start = (VR_START[0], float(rng.integers(-20, 21)) * cm)
    target = SceneObject(
        name="Target",
        shape="cylinder",
        x=VR_TARGET_X,
        y=float(rng.integers(-25, 26)) * cm,
        size=VR_TARGET_SIZE,
    )
    occupied = [footprint(target), _keep_clear(start, 0.025)]
    names = list(VR_OBSTACLE_WIDTHS)
    half = VR_TABLE.width / 2.0

    def make(index: int) -> Callable[[], SceneObject]:
        size_name = names[index % 3]

        def draw() -> SceneObject:
            width = VR_OBSTACLE_WIDTHS[size_name]
            y_steps = math.floor((half - width / 2.0) / cm)
            return SceneObject(
                name=f"{VR_OBSTACLE_PREFIX}{size_name}" + ("" if index < 3 else f"-{index // 3}"),
                shape="box",
                x=0.35 + float(rng.integers(-18, 17)) * cm,  # dataset: Unity z in [-0.185, 0.165]
                y=float(rng.integers(-y_steps, y_steps + 1)) * cm,
                size=(VR_OBSTACLE_DEPTH, width, VR_OBSTACLE_HEIGHT),
            )

        return draw

    obstacles = tuple(
        _place_at_random(rng, make(i), occupied, VR_MIN_GAP, f"obstacle {i + 1} of {objects}")
        for i in range(objects)
    )
    return finished(
        Scene(table=VR_TABLE, start=start, target=target, obstacles=obstacles, name=f"unstructured-{seed}")
    )


FIXED_OBJECT_COUNT = {"vr": 6, "gen1": 6}


def generate_scene(
    kind: str, seed: int, objects: int | None = None, workspace: Workspace | None = None
) -> Scene:
    """Generate a scene of ``kind`` (one of ``KINDS``) from ``seed``.

    Args:
        kind: "vr", "gen1", "gen2" or "unstructured".
        seed: the random seed; the same seed always gives the same scene.
        objects: number of obstacles (gen2: default 7; unstructured: default 6; vr and gen1: 6 only).
        workspace: a fixed robot's reach: gen1 and gen2 tables within it (``within_reach``).
    """
    if kind not in KINDS:
        raise SceneError(f"unknown scene kind {brief(kind)} (expected one of {', '.join(KINDS)})")
    if not isinstance(seed, int | np.integer) or not 0 <= seed <= MAX_SEED:
        raise SceneError(f"the seed must be an integer between 0 and {MAX_SEED}, got {brief(seed)}")
    if objects is not None and (not isinstance(objects, int | np.integer) or objects > MAX_GENERATED):
        raise SceneError(
            f"the number of obstacles must be an integer of at most {MAX_GENERATED}, got {brief(objects)}"
        )
    if kind in FIXED_OBJECT_COUNT:
        if objects is not None and objects != FIXED_OBJECT_COUNT[kind]:
            raise SceneError(
                f"{kind} scenes always have {FIXED_OBJECT_COUNT[kind]} obstacles, got --objects {objects}"
            )
        return generate_vr(seed) if kind == "vr" else generate_gen1(seed, within_reach(GEN1, workspace))
    if kind == "gen2":
        return generate_gen2(seed, 7 if objects is None else objects, within_reach(GEN1, workspace))
    return generate_unstructured(seed, 6 if objects is None else objects)
