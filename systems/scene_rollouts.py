"""``SceneRollouts``: the rollouts of one scenario, on its full world or on reduced ones.

The reduced model (``optimiser.reduced_model``): most of a rollout's time goes to the contact problem,
which every resting object joins with its contact points on the table. An object nothing has come
near stays at rest, so until then it can as well be welded (``weld_schedule``, ``rollout_sampler``).
Every cost term still covers every object: a welded one simply stays put.
"""

from __future__ import annotations

from collections import OrderedDict
from typing import TYPE_CHECKING

from hlp_drake.systems.control_sequence import ControlSequence
from hlp_drake.systems.rollout_cost import RolloutOutcome, RolloutSamples
from hlp_drake.systems.rollout_sampler import sample_rollout
from hlp_drake.systems.rollout_world import RolloutWorld, timed_rollout
from hlp_drake.systems.weld_schedule import FixedWelds, Sweep, WeldSchedule

if TYPE_CHECKING:
    from hlp_drake.systems.scenario import Scenario


class SceneRollouts:
    """Rollouts on one scene: on the full world, or with ``sto.reduced_model`` on reduced worlds
    (see the module's docstring), built on first use and the latest ``worlds_kept`` kept.

    A rollout's outcome is a pure function of the scene, the configuration and the sequence: which
    objects are welded when follows from the sequence alone, whichever worlds happen to be built.
    """

    def __init__(self, scenario: Scenario, *, worlds_kept: int = 32) -> None:
        self.full = RolloutWorld(scenario)
        self.scenario = scenario
        self._worlds_kept = worlds_kept
        self._reduced: OrderedDict[frozenset[str], RolloutWorld] = OrderedDict()
        self._sweep = Sweep(self.full) if scenario.optimiser.reduced_model else None

    @property
    def start_collisions(self) -> tuple[str, ...]:
        return self.full.start_collisions

    def world_with(self, welded: frozenset[str]) -> RolloutWorld:
        """The world with the objects ``welded`` welded (the full one when empty)."""
        if not welded:
            return self.full
        if welded not in self._reduced:
            self._reduced[welded] = RolloutWorld(self.scenario, welded_objects=welded)
            while len(self._reduced) > self._worlds_kept:
                self._reduced.popitem(last=False)
        self._reduced.move_to_end(welded)
        return self._reduced[welded]

    def weld_schedule(self, sequence: ControlSequence) -> WeldSchedule | FixedWelds:
        """The objects the robot's commanded motion does not come within ``optimiser.weld_clearance``
        of before ``t + optimiser.weld_lookahead`` (none with the reduced model off)."""
        sto = self.scenario.optimiser
        if self._sweep is None:
            return FixedWelds(frozenset())
        return WeldSchedule(self._sweep.approach_times(sequence, sto.weld_clearance), sto.weld_lookahead)

    def simulate(self, sequence: ControlSequence) -> RolloutSamples:
        """Roll ``sequence`` out on the reduced worlds (or the full one), reading the state every sample period."""
        return sample_rollout(sequence, self.scenario.optimiser, self, self.weld_schedule(sequence))

    def rollout(self, sequence: ControlSequence) -> RolloutOutcome:
        """Simulate ``sequence`` and cost it."""
        return timed_rollout(sequence, self.simulate, self.full)
