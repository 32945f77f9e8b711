"""VR layouts and tracks -> the project's Scene and Tracks (via ``hlp_drake.dataset.frames``)."""

from __future__ import annotations

import numpy as np

from hlp_drake.dataset.frames import unity_to_world, unity_yaw_to_world
from hlp_drake.dataset.records import Track
from hlp_drake.scene.model import Scene, SceneObject, Table
from hlp_drake.scene.validation import validate_scene

TARGET = "Target"
ORIGIN_DECIMALS = 4  # the table pose is recorded with float32 noise (depth 0.6000001): snap to 0.1 mm
START_TOLERANCE = 1e-3  # m: a scene file's start x further than this from trial_results' is stale


def _layout_rows(scene_layout: list[list]) -> dict[str, list]:
    rows = {row[0]: row[1:] for row in scene_layout}
    for name in ("TableTop", "StartPoint"):
        if name not in rows:
            raise ValueError(f"no {name} row")
    return rows


def stale_start(scene_layout: list[list], start_x: float | None) -> float | None:
    """The scene file's StartPoint x (Unity) if ``trial_results.csv``'s ``start_pos_x`` differs
    from it by more than ``START_TOLERANCE`` (in every T100 the scene file keeps 0), else None."""
    recorded = _layout_rows(scene_layout)["StartPoint"][0]
    if start_x is None or abs(start_x - recorded) <= START_TOLERANCE:
        return None
    return recorded


class TableFrame:
    """Where the table sits in Unity, which fixes the world frame of a trial.

    Args:
        scene_layout: the parsed scene layout file.
        start_x: ``trial_results.csv``'s ``start_pos_x`` (Unity x) where known: the start's
            lateral position, which the hand track confirms; the scene file's can be stale.
    """

    def __init__(self, scene_layout: list[list], start_x: float | None = None) -> None:
        rows = _layout_rows(scene_layout)
        x, y, z, width, height, depth = rows["TableTop"]
        self.center_x = round(x, ORIGIN_DECIMALS)
        self.front_z = round(z - depth / 2.0, ORIGIN_DECIMALS)
        self.table = Table(length=depth, width=width, height=y + height / 2.0)
        unity = np.array(rows["StartPoint"][:3], dtype=float)
        if start_x is not None:
            unity[0] = start_x
        start = self.to_world(unity)
        self.start = (float(start[0]), float(start[1]))

    def to_world(self, points: np.ndarray) -> np.ndarray:
        return unity_to_world(points, table_front_z=self.front_z, table_center_x=self.center_x)

    def track(self, name: str, block: np.ndarray) -> Track:
        """A (N, 7) movement block (time, pos, rot in Unity) -> world Track."""
        return Track(
            name=name,
            time=np.array(block[:, 0]),
            position=self.to_world(block[:, 1:4]),
            yaw=np.asarray(unity_yaw_to_world(block[:, 5])),
            rotation_unity_deg=np.array(block[:, 4:7]),
        )


def scene_from_layouts(
    scene_layout: list[list], objects_layout: list[list], name: str, *, start_x: float | None = None
) -> Scene:
    """Build and validate the Scene of a trial from its two layout files (rows as parsed) and
    ``trial_results.csv``'s start (``start_x``, Unity x; see ``TableFrame``).

    Raises:
        ValueError: a row is missing. SceneError: the layout is not a valid scene.
    """
    frame = TableFrame(scene_layout, start_x)
    target = None
    obstacles = []
    for obj_name, x, y, z, width, height, depth in objects_layout:
        wx, wy, _ = frame.to_world(np.array([x, y, z]))
        if obj_name == TARGET:
            diameter = (width + depth) / 2.0  # recorded as e.g. 0.04999959 x 0.04999948
            target = SceneObject(TARGET, "cylinder", float(wx), float(wy), (diameter, diameter, height))
        else:
            obstacles.append(SceneObject(obj_name, "box", float(wx), float(wy), (depth, width, height)))
    if target is None:
        raise ValueError("no Target row")
    scene = Scene(table=frame.table, start=frame.start, target=target, obstacles=tuple(obstacles), name=name)
    return validate_scene(scene)
