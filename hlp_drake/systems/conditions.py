"""``Conditions``: what a run's command line, or one cell of a study's grid, sets over a scenario.

The one way options become a ``Scenario``: ``run_scene``'s flags, the experiments' flags and a
study's grid cells are each a ``Conditions``, applied by ``Conditions.applied``. The bundled default
scene, drawn for the mobile UR5, is scaled there to a fixed robot's reach (``scene_for_robot``).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

from hlp_drake.systems.low_level.registry import low_level_entry
from hlp_drake.systems.planning.initialisers import initialiser_name
from hlp_drake.systems.world.robot_description import RobotDescription, load_robot

if TYPE_CHECKING:
    from hlp_drake.scene.model import Scene
    from hlp_drake.systems.scenario import Scenario


@dataclass(frozen=True)
class Conditions:
    """Settings laid over a scenario; None leaves the scenario's.

    Attributes:
        robot: a shipped robot's name or a robot description file (``load_robot``).
        initial: the initialiser (``INITIALISERS``; ``sto`` for ``line``).
        low_level: the low-level planner (``LOW_LEVEL_PLANNERS``); another than the scenario's
            starts from its default settings.
        execution: "open" (play the planned motion) or "closed" (the receding-horizon controller).
        uncertainty: the seed of the model error the world has and the planners do not know of.
        perception: "truth" (the plant's poses) or "camera" (the cameras' perception).
        world: what the robot acts in and the run is judged in: "reference" or "model" (``WorldConfig``).
        workers: rollout processes of a low-level planner that rolls out (others ignore it).
    """

    robot: str | None = None
    initial: str | None = None
    low_level: str | None = None
    execution: str | None = None
    uncertainty: int | None = None
    perception: str | None = None
    world: str | None = None
    workers: int | None = None

    def applied(self, scenario: Scenario, *, scene: Scene | None = None) -> Scenario:
        """``scenario`` under these conditions, on ``scene`` if given (None: its own), checked once; the
        bundled default scene scaled to a fixed robot's reach (``scene_for_robot``).

        Raises:
            HlpError: an unknown robot, initialiser or low-level planner, or settings that do not
                fit together (e.g. a camera source without a camera), one line each.
        """
        changes: dict = {} if scene is None else {"scene": scene}
        if self.robot is not None:
            changes["robot"] = load_robot(self.robot)
        planner = self._planner(scenario)
        if planner is not scenario.planner:
            changes["planner"] = planner
        if self.execution is not None:
            changes["closed_loop"] = replace(scenario.closed_loop, enabled=self.execution == "closed")
        if self.uncertainty is not None:
            changes["uncertainty"] = replace(scenario.uncertainty, enabled=True, seed=int(self.uncertainty))
        if self.perception is not None:
            changes["perception"] = replace(scenario.perception, source=self.perception)
        if self.world is not None and self.world != scenario.world.kind:
            changes["world"] = replace(scenario.world, kind=self.world)
        on = changes.get("scene", scenario.scene)
        fitted = scene_for_robot(on, changes.get("robot", scenario.robot))
        if fitted is not on:
            changes["scene"] = fitted
        return replace(scenario, **changes) if changes else scenario  # checked as it is made

    def _planner(self, scenario: Scenario):
        """The scenario's ``planner`` section under these conditions (itself if unchanged)."""
        planner = scenario.planner
        if self.initial is not None and initialiser_name(self.initial) != planner.initial:
            planner = replace(planner, initial=initialiser_name(self.initial))
        if self.low_level is not None and self.low_level != planner.low_level.kind:
            planner = replace(planner, low_level=low_level_entry(self.low_level).config_class()())
        low_level = planner.low_level
        if self.workers is not None and getattr(low_level, "workers", self.workers) != self.workers:
            planner = replace(planner, low_level=replace(low_level, workers=self.workers))
        return planner


def scene_for_robot(scene: Scene, robot: RobotDescription) -> Scene:
    """``scene``, or for the bundled default scene (drawn for the mobile UR5) on a fixed robot, the
    default scaled to its reach as the generators scale their tables (``scaled_to_reach``: the same
    as gen1 seed 3 generated for that robot). Any other scene is the user's: never changed."""
    from hlp_drake.scene.io import default_scene
    from hlp_drake.scene.scaled import scaled_to_reach

    if robot.mobile or scene != default_scene():
        return scene
    return scaled_to_reach(scene, robot.workspace, robot.name)


def rollout_workers(scenario: Scenario) -> int | None:
    """The rollout processes the scenario's low-level planner needs (None: it does not roll out)."""
    entry = low_level_entry(scenario.low_level.kind)
    return getattr(scenario.low_level, "workers", 1) if entry.rolls_out else None


__all__ = ["Conditions", "rollout_workers", "scene_for_robot"]
