"""Seeded model error between what the planners believe and the simulated world (``--uncertainty``).

With ``uncertainty.enabled`` the world a run executes in differs from the scenario the planners and
the optimiser's rollouts use: every object (the target too) stands elsewhere (Gaussian offsets of
``position_sigma`` per axis and ``yaw_sigma``), weighs ``mass_scale`` times as much (log-uniform in
the range) and has ``friction_scale`` times its friction (uniform). The error is a pure function of
``uncertainty.seed`` and the scene's name, so both planners meet the same world on a scene, and the
same seed gives the same world. An offset that would make the scene invalid (an object off the table,
overlapping another or the start) is halved until it does not (at worst the object stays put).
"""

from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass, replace
from typing import Annotated

import numpy as np

from hlp_drake.config.ranges import MAX_SEED, Between, Rule
from hlp_drake.scene.model import Scene, SceneObject
from hlp_drake.scene.validation import scene_problems

SHRINKS = 4
"""Halvings of an offset that makes the scene invalid before the object is left where it was."""
MAX_SCALE = 100.0
"""The largest factor of ``uncertainty``'s mass and friction ranges."""
SCALE = Rule(
    lambda v: 1.0 / MAX_SCALE <= v[0] <= v[1] <= MAX_SCALE,
    f"{{where}} must be [low, high] with {1.0 / MAX_SCALE:g} <= low <= high <= {MAX_SCALE:g}, "
    "got [{value[0]:g}, {value[1]:g}]",
)
"""A range of factors: [low, high], within [1 / MAX_SCALE, MAX_SCALE]."""


@dataclass(frozen=True)
class UncertaintyConfig:
    """The model error of ``--uncertainty`` (a ``Scenario``'s ``uncertainty``).

    Attributes:
        enabled: execute in a world that differs from the believed scenario as below.
        seed: seed of the error (mixed with the scene's name).
        position_sigma: standard deviation of an object's offset along x and along y, m.
        yaw_sigma: standard deviation of an object's turn about z, rad (3 degrees).
        mass_scale: range of the factor on an object's mass (drawn log-uniformly).
        friction_scale: range of the factor on an object's friction coefficient (uniformly).
    """

    enabled: bool = False
    seed: Annotated[int, Between(0, MAX_SEED)] = 0
    position_sigma: Annotated[float, Between(0.0, 0.5, "m")] = 0.01
    yaw_sigma: Annotated[float, Between(0.0, math.pi, "rad")] = math.radians(3.0)
    mass_scale: Annotated[tuple[float, float], SCALE] = (0.5, 2.0)
    friction_scale: Annotated[tuple[float, float], SCALE] = (0.7, 1.3)


@dataclass(frozen=True)
class ObjectPerturbation:
    """How one object of the world differs from the believed one."""

    dx: float
    dy: float
    dyaw: float
    mass_scale: float
    friction_scale: float


@dataclass(frozen=True)
class WorldPerturbation:
    """The world's differences from the believed scene (its model error), per object name."""

    objects: dict[str, ObjectPerturbation]

    def true_scene(self, scene: Scene) -> Scene:
        """``scene`` with every object where the world has it."""

        def moved(obj: SceneObject) -> SceneObject:
            e = self.objects.get(obj.name)
            return obj if e is None else obj.moved(obj.x + e.dx, obj.y + e.dy, obj.yaw + e.dyaw)

        return replace(scene, target=moved(scene.target), obstacles=tuple(moved(o) for o in scene.obstacles))

    def scales(self) -> dict[str, tuple[float, float]]:
        """Per object name, (mass factor, friction factor)."""
        return {name: (e.mass_scale, e.friction_scale) for name, e in self.objects.items()}


def _seed(config: UncertaintyConfig, scene: Scene) -> np.random.Generator:
    digest = int.from_bytes(hashlib.sha256(scene.name.encode()).digest()[:8], "little")
    return np.random.default_rng([int(config.seed), digest])


def sample_perturbation(config: UncertaintyConfig, scene: Scene) -> WorldPerturbation:
    """The seeded perturbation (model error) of ``scene``'s world (see the module's docstring)."""
    rng = _seed(config, scene)
    low_m, high_m = config.mass_scale
    low_f, high_f = config.friction_scale
    drawn: dict[str, ObjectPerturbation] = {}
    placed = scene
    for obj in scene.objects:
        dx, dy = rng.normal(0.0, config.position_sigma, size=2)
        dyaw = float(rng.normal(0.0, config.yaw_sigma))
        mass = float(math.exp(rng.uniform(math.log(low_m), math.log(high_m))))
        friction = float(rng.uniform(low_f, high_f))
        before = set(scene_problems(placed))
        for shrink in range(SHRINKS + 1):
            factor = 0.5**shrink if shrink < SHRINKS else 0.0
            offset = ObjectPerturbation(float(factor * dx), float(factor * dy), factor * dyaw, mass, friction)
            trial = WorldPerturbation({**drawn, obj.name: offset}).true_scene(scene)
            if set(scene_problems(trial)) <= before:
                break
        drawn[obj.name] = offset
        placed = WorldPerturbation(drawn).true_scene(scene)
    return WorldPerturbation(drawn)


def displaced_scenes(scene: Scene, count: int, position_sigma: float, yaw_sigma: float) -> list[Scene]:
    """``count`` copies of ``scene`` with every object displaced (``sample_perturbation`` with seeds
    1 ... count, positions and yaw only: masses and friction as believed)."""
    return [
        sample_perturbation(
            UncertaintyConfig(True, seed, position_sigma, yaw_sigma, (1.0, 1.0), (1.0, 1.0)), scene
        ).true_scene(scene)
        for seed in range(1, count + 1)
    ]


__all__ = [
    "ObjectPerturbation",
    "UncertaintyConfig",
    "WorldPerturbation",
    "displaced_scenes",
    "sample_perturbation",
]
