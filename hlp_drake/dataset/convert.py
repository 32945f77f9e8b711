"""VR layouts and tracks -> the project's Scene and Tracks (via ``hlp_drake.frames``)."""

from __future__ import annotations

import numpy as np

from hlp_drake.dataset.records import Track
from hlp_drake.frames import unity_to_world, unity_yaw_to_world
from hlp_drake.scene.model import Scene, SceneObject, Table
from hlp_drake.scene.validation import validate_scene

TARGET = "Target"
ORIGIN_DECIMALS = 4  # the table pose is recorded with float32 noise (depth 0.6000001): snap to 0.1 mm


class TableFrame:
    """Where the table sits in Unity, which fixes the world frame of a trial."""

    def __init__(self, scene_layout: list[list]) -> None:
        rows = {row[0]: row[1:] for row in scene_layout}
        for name in ("TableTop", "StartPoint"):
            if name not in rows:
                raise ValueError(f"no {name} row")
        x, y, z, width, height, depth = rows["TableTop"]
        self.center_x = round(x, ORIGIN_DECIMALS)
        self.front_z = round(z - depth / 2.0, ORIGIN_DECIMALS)
        self.table = Table(length=depth, width=width, height=y + height / 2.0)
        start = self.to_world(np.array(rows["StartPoint"][:3]))
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


def scene_from_layouts(scene_layout: list[list], objects_layout: list[list], name: str) -> Scene:
    """Build and validate the Scene of a trial from its two layout files (rows as parsed).

    Raises:
        ValueError: a row is missing. SceneError: the layout is not a valid scene.
    """
    frame = TableFrame(scene_layout)
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
