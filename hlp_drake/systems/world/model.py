"""``WorldModel``: what a simulated world is made of besides its scene.

The robot (and, through ``ik``, its start pose), the plant's physics (``plant``: time step, contact
model and approximation), the contact materials and geometry (``contact``), how the scene becomes
bodies (``bodies``) and the robot's controller. A ``Scenario`` holds these as its own sections
(``Scenario.world_model`` gathers them); the world diagram (``world_diagram``) and the rollout
worlds of a planner that simulates are built from a scene and a ``WorldModel``.
"""

from __future__ import annotations

import copy
import hashlib
from dataclasses import dataclass, field, replace

from pydrake.multibody.plant import MultibodyPlantConfig

from hlp_drake.config.typed_yaml import dump_typed
from hlp_drake.scene.model import Scene
from hlp_drake.systems.planning.config import IkConfig
from hlp_drake.systems.world.robot_description import RobotDescription
from hlp_drake.systems.world.scene_models import BodiesConfig, ContactConfig
from hlp_drake.systems.world.world_config import ControlConfig, default_plant_config


@dataclass(frozen=True)
class WorldModel:
    """A world's robot and physics (see the module's docstring); the defaults are a ``Scenario``'s."""

    robot: RobotDescription = field(default_factory=RobotDescription)
    plant: MultibodyPlantConfig = field(default_factory=default_plant_config)
    contact: ContactConfig = field(default_factory=ContactConfig)
    bodies: BodiesConfig = field(default_factory=BodiesConfig)
    controller: ControlConfig = field(default_factory=ControlConfig)
    ik: IkConfig = field(default_factory=IkConfig)

    def stepped(self, time_step: float, *, sampled: bool | None = None) -> WorldModel:
        """This model with its plant stepping at ``time_step`` s (and its outputs from the sampled
        state if ``sampled`` says so; None: as they are)."""
        plant = copy.copy(self.plant)  # Drake's MultibodyPlantConfig, not a dataclass
        plant.time_step = time_step
        if sampled is not None:
            plant.use_sampled_output_ports = sampled
        return replace(self, plant=plant)


def world_key(scene: Scene, model: WorldModel, settle_s: float) -> str:
    """Identifies where a motion ends in a world: equal for the same ``scene`` in the same ``model``,
    read ``settle_s`` after the motion (the world is deterministic, so the same motion from the same
    start ends in the same state there)."""
    text = f"{dump_typed(scene)}\n{dump_typed(model)}\nsettle_s: {settle_s!r}\n"
    return hashlib.sha256(text.encode()).hexdigest()


__all__ = ["WorldModel", "world_key"]
