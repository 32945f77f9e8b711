"""``scaled_to_reach``: a scene drawn for the mobile UR5 (the bundled default) scaled to a fixed
robot's reach, as the generators scale the tables they draw for it (``reach_scale``)."""

from __future__ import annotations

from dataclasses import replace

from hlp_drake.scene.generators import GEN1, finished
from hlp_drake.scene.model import Scene, SceneObject, Table
from hlp_drake.scene.workspace import Workspace, reach_scale


def scaled_to_reach(scene: Scene, workspace: Workspace | None, robot: str) -> Scene:
    """``scene`` scaled by the factor the generators scale their tables by for ``workspace``
    (``reach_scale`` of ``GEN1``), as they scale: the table's length and width, every position on it and
    the obstacles' footprints; heights, the start's heading and the target's size (the gripper's) kept.
    Its name says so ("..., scaled to the ROBOT's reach x0.59"); ``scene`` itself at a factor of 1.

    Raises:
        SceneError: the robot reaches too little of a table (``reach_scale``), or the scaled scene is
            not valid (e.g. the target now overlaps an obstacle).
    """
    scale = reach_scale(GEN1, workspace)
    if scale == 1.0:
        return scene

    def scaled(obj: SceneObject) -> SceneObject:
        size = obj.size if obj is scene.target else (obj.size[0] * scale, obj.size[1] * scale, obj.size[2])
        return replace(obj, x=obj.x * scale, y=obj.y * scale, size=size)

    table = scene.table
    return finished(
        replace(
            scene,
            table=Table(table.length * scale, table.width * scale, table.height),
            start=(scene.start[0] * scale, scene.start[1] * scale),
            target=scaled(scene.target),
            obstacles=tuple(scaled(o) for o in scene.obstacles),
            name=f"{scene.name}, scaled to the {robot}'s reach x{scale:.2f}",
        )
    )


__all__ = ["scaled_to_reach"]
