"""When a rollout's objects sleep: ``SleepSchedule`` (from the commanded sweep) or ``AWAKE`` (never).

A rollout starts with the objects asleep (their joints locked) that the robot's collision geometry,
following the commanded motion (``Sweep.approach_times``), does not come within
``optimiser.weld_clearance`` of in the next ``optimiser.weld_lookahead`` seconds, and wakes each
that long before the motion comes near it. Between, ``rollout_sampler`` wakes an object anything
comes near and puts objects that have come to rest back to sleep.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from hlp_drake.systems.control_sequence import ControlSequence
from hlp_drake.systems.proximity import ProximityContext

if TYPE_CHECKING:
    from hlp_drake.systems.rollout_world import RolloutWorld


@dataclass(frozen=True)
class SleepSchedule:
    """The objects' first approach by the commanded motion (``approach``: s, inf if never) and how
    long before it an object is woken (``lookahead``); ``sleeping``: whether objects sleep at all."""

    approach: dict[str, float]
    lookahead: float
    sleeping: bool = True

    def initially_asleep(self) -> frozenset[str]:
        return frozenset(n for n, first in self.approach.items() if self.sleeping and first > self.lookahead)

    def due(self, t: float) -> frozenset[str]:
        """The objects to be awake by ``t`` (their approach is at most ``lookahead`` away)."""
        return frozenset(n for n, first in self.approach.items() if first <= t + self.lookahead)

    def approaching(self, t: float) -> frozenset[str]:
        """The objects not to put to sleep at ``t``: the motion comes near them within ``lookahead``."""
        return frozenset(n for n, first in self.approach.items() if t <= first <= t + self.lookahead)


AWAKE = SleepSchedule({}, 0.0, sleeping=False)
"""Every object awake throughout (the full model)."""


class Sweep:
    """The robot's collision geometry following a commanded motion through a full world's scene, the
    objects at their scene poses, in a ``ProximityContext`` of its own checking robot-object pairs only."""

    def __init__(self, world: RolloutWorld) -> None:
        self._world = world
        self._proximity = ProximityContext(world, objects_apart=True)

    def approach_times(
        self, sequence: ControlSequence, clearance: float, states: dict[str, np.ndarray] | None = None
    ) -> dict[str, float]:
        """Per object, the first time the robot's collision geometry comes within ``clearance`` of it
        when following ``sequence``'s commanded motion exactly, the objects at their scene poses or
        as ``states`` has them (a ``RolloutStart``'s; checked every sample period and at every knot;
        inf if never)."""
        world, proximity = self._world, self._proximity
        for body in world.objects:
            x = None if states is None else states.get(body.name())
            instance = body.model_instance()
            q = (
                world.plant.GetDefaultPositions(instance)
                if x is None
                else x[: world.plant.num_positions(instance)]
            )
            proximity.set_instance_positions(instance, q)
        trajectory = sequence.to_trajectory()
        names = {int(b.index()): b.name() for b in world.objects}
        first = {obj.name: math.inf for obj in world.scene.objects}
        period = world.scenario.optimiser.sample_period
        times = np.union1d(sequence.times, np.arange(0.0, sequence.duration, period))
        for t in times:
            proximity.set_instance_positions(world.robot, trajectory.value(t).ravel())
            for pair in proximity.close_pairs(clearance):
                for body in pair[:2]:
                    name = names.get(body)
                    if name is not None and first[name] == math.inf:
                        first[name] = float(t)
        return first
