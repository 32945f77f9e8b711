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

import numpy as np

from hlp_drake.scene.model import Scene, SceneObject
from hlp_drake.scene.validation import scene_problems

SHRINKS = 4
"""Halvings of an offset that makes the scene invalid before the object is left where it was."""


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
    seed: int = 0
    position_sigma: float = 0.01
    yaw_sigma: float = math.radians(3.0)
    mass_scale: tuple[float, float] = (0.5, 2.0)
    friction_scale: tuple[float, float] = (0.7, 1.3)


@dataclass(frozen=True)
class ObjectError:
    """How one object of the world differs from the believed one."""

    dx: float
    dy: float
    dyaw: float
    mass_scale: float
    friction_scale: float


@dataclass(frozen=True)
class ModelError:
    """The world's differences from the believed scene, per object name."""

    objects: dict[str, ObjectError]

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


def sample_model_error(config: UncertaintyConfig, scene: Scene) -> ModelError:
    """The seeded error of ``scene``'s world (see the module's docstring)."""
    rng = _seed(config, scene)
    low_m, high_m = config.mass_scale
    low_f, high_f = config.friction_scale
    errors: dict[str, ObjectError] = {}
    placed = scene
    for obj in scene.objects:
        dx, dy = rng.normal(0.0, config.position_sigma, size=2)
        dyaw = float(rng.normal(0.0, config.yaw_sigma))
        mass = float(math.exp(rng.uniform(math.log(low_m), math.log(high_m))))
        friction = float(rng.uniform(low_f, high_f))
        before = set(scene_problems(placed))
        for shrink in range(SHRINKS + 1):
            factor = 0.5**shrink if shrink < SHRINKS else 0.0
            error = ObjectError(float(factor * dx), float(factor * dy), factor * dyaw, mass, friction)
            trial = ModelError({**errors, obj.name: error}).true_scene(scene)
            if set(scene_problems(trial)) <= before:
                break
        errors[obj.name] = error
        placed = ModelError(errors).true_scene(scene)
    return ModelError(errors)


def displaced_scenes(scene: Scene, count: int, position_sigma: float, yaw_sigma: float) -> list[Scene]:
    """``count`` copies of ``scene`` with every object displaced (``sample_model_error`` with seeds
    1 ... count, positions and yaw only: masses and friction as believed)."""
    return [
        sample_model_error(
            UncertaintyConfig(True, seed, position_sigma, yaw_sigma, (1.0, 1.0), (1.0, 1.0)), scene
        ).true_scene(scene)
        for seed in range(1, count + 1)
    ]


__all__ = ["ModelError", "ObjectError", "UncertaintyConfig", "displaced_scenes", "sample_model_error"]
