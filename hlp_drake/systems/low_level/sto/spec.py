"""``RolloutSpec``: what a rollout simulates: a scene in a world model, sampled, settled and costed
as the optimiser's settings say. The rollout pool keys its worlds by ``RolloutSpec.key`` and sends a
worker process the spec as YAML text (``yaml``, read back by ``from_yaml``)."""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from functools import cached_property
from typing import TYPE_CHECKING

from hlp_drake.config.typed_yaml import Documented, load_typed
from hlp_drake.files.documents import parse_yaml
from hlp_drake.scene.model import Scene
from hlp_drake.systems.low_level.sto.config import StoConfig
from hlp_drake.systems.world.model import WorldModel, world_key
from hlp_drake.systems.world.success import SuccessConfig

if TYPE_CHECKING:
    from hlp_drake.systems.scenario import Scenario


@dataclass(frozen=True)
class RolloutSpec(Documented):
    """``scene`` in the world ``model``, rolled out as ``sto`` says (its sampling, cost and reduced
    model) and judged by the ``success`` test. A rollout is a pure function of its spec, its start
    and its sequence."""

    scene: Scene
    model: WorldModel
    sto: StoConfig
    success: SuccessConfig = field(default_factory=SuccessConfig)

    @cached_property
    def world_key(self) -> str:
        """Identifies the world its rollouts simulate (``world_key``; computed once)."""
        return world_key(self.scene, self.model, self.success.settle_s)

    def with_scene(self, scene: Scene) -> RolloutSpec:
        """This spec on ``scene`` (itself, with its computed key, when the scene is its own)."""
        return self if scene == self.scene else replace(self, scene=scene)

    @classmethod
    def of(cls, scenario: Scenario) -> RolloutSpec:
        """What ``scenario``'s STO rolls out: its scene, world model, STO settings (its low-level
        planner's, which must be the STO's) and success test."""
        from hlp_drake.systems.low_level.sto.first_rollout import sto_config

        return cls(scenario.scene, scenario.world_model, sto_config(scenario), scenario.success)

    @classmethod
    def from_yaml(cls, text: str) -> RolloutSpec:
        """The spec of ``yaml``'s text."""
        return load_typed(cls, parse_yaml(text, "a rollout spec"), where="a rollout spec")


__all__ = ["RolloutSpec"]
