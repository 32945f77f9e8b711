"""Scene dataclasses: a table, a start point, a target cylinder and obstacles, in the world frame.

See ``hlp_drake.dataset.frames`` for the frame: origin below the middle of the table's front edge, x into
the table (depth), y to the left, z up. Objects stand on the table top; a scene stores only their
planar pose (x, y, yaw) and their size.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass, field, replace
from typing import Protocol, TypeVar

SHAPES = ("box", "cylinder")


class _PlanarPosition(Protocol):
    x: float
    y: float


Placed = TypeVar("Placed", bound=_PlanarPosition)


@dataclass(frozen=True)
class Table:
    """A rectangular table top spanning x in [0, length] and y in [-width/2, width/2].

    Attributes:
        length: extent along x (depth, away from the start), m.
        width: extent along y (lateral), m.
        height: height of the top surface above the floor, m.
    """

    length: float
    width: float
    height: float

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """(x_min, y_min, x_max, y_max) of the table top."""
        return (0.0, -self.width / 2.0, self.length, self.width / 2.0)

    @property
    def diagonal(self) -> float:
        return math.hypot(self.length, self.width)


@dataclass(frozen=True)
class SceneObject:
    """A box or an upright cylinder standing on the table.

    Attributes:
        name: unique name in the scene (the dataset's name for VR scenes).
        shape: "box" or "cylinder".
        x, y: centre of the footprint in the world frame, m.
        size: (extent along the object's own x, extent along its own y, height), m. A cylinder's
            first two entries are both its diameter.
        yaw: rotation about world z, radians (0: the object's x along world x).
    """

    name: str
    shape: str
    x: float
    y: float
    size: tuple[float, float, float]
    yaw: float = 0.0

    @property
    def position(self) -> tuple[float, float]:
        return (self.x, self.y)

    @property
    def height(self) -> float:
        return self.size[2]

    def moved(self, x: float, y: float, yaw: float | None = None) -> SceneObject:
        """A copy at another planar pose."""
        return replace(self, x=x, y=y, yaw=self.yaw if yaw is None else yaw)


@dataclass(frozen=True)
class Scene:
    """A reaching problem: reach ``target`` from ``start`` past ``obstacles`` on ``table``.

    Attributes:
        table: the table.
        start: (x, y) where the hand / gripper starts, on the table top.
        target: the object to reach (an upright cylinder).
        obstacles: the other objects.
        start_yaw: heading of the gripper at the start, radians (0: facing +x).
        name: free-form label (e.g. "sub_01/T050" or "gen2-seed7").
    """

    table: Table
    start: tuple[float, float]
    target: SceneObject
    obstacles: tuple[SceneObject, ...] = field(default_factory=tuple)
    start_yaw: float = 0.0
    name: str = ""

    @property
    def objects(self) -> tuple[SceneObject, ...]:
        """The target followed by the obstacles."""
        return (self.target, *self.obstacles)

    def obstacle(self, name: str) -> SceneObject:
        for obstacle in self.obstacles:
            if obstacle.name == name:
                return obstacle
        raise KeyError(f"no obstacle named {name!r}")


def plan_view_order(objects: Iterable[Placed]) -> list[Placed]:
    """``objects`` by x (away from the start's edge), then y: the order worlds are built in (and a
    camera names what it finds in), so how a scene lists its objects cannot change a simulation."""
    return sorted(objects, key=lambda o: (o.x, o.y))
