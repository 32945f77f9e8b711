"""``SceneRollouts``: the rollouts of one scenario on its rollout model, and their verification.

The reduced model (``optimiser.reduced_model``): most of a rollout's time goes to the contact problem,
which every resting object joins with its contact points on the table. An object nothing has come
near stays at rest, so until then it can as well sleep (its joint locked; ``sleep_schedule``,
``rollout_sampler``); one that has come to rest again goes back to sleep. Every cost term still
covers every object. ``verify`` rolls a sequence out on the execution model instead
(``RolloutWorld(..., execution=True)``).
"""

from __future__ import annotations

from functools import cached_property
from typing import TYPE_CHECKING

from hlp_drake.systems.control_sequence import ControlSequence
from hlp_drake.systems.rollout_cost import RolloutOutcome, RolloutSamples
from hlp_drake.systems.rollout_sampler import sample_rollout
from hlp_drake.systems.rollout_world import RolloutStart, RolloutWorld, timed_rollout
from hlp_drake.systems.sleep_schedule import AWAKE, SleepSchedule, Sweep

if TYPE_CHECKING:
    from hlp_drake.systems.scenario import Scenario


class SceneRollouts:
    """Rollouts on one scene: on the rollout model's world, with ``sto.reduced_model`` its objects
    asleep while nothing comes near them (see the module's docstring); verification on the
    execution model's (each world built on first use).

    A rollout's outcome is a pure function of the scene, the configuration, the start and the sequence.
    """

    def __init__(self, scenario: Scenario) -> None:
        self.scenario = scenario
        self._execution: RolloutWorld | None = None

    @cached_property
    def full(self) -> RolloutWorld:
        """The rollout model's world (built on first use: a world only verified on needs none)."""
        return RolloutWorld(self.scenario)

    @cached_property
    def _sweep(self) -> Sweep | None:
        return Sweep(self.full) if self.scenario.optimiser.reduced_model else None

    @property
    def start_collisions(self) -> tuple[str, ...]:
        return self.full.start_collisions

    def sleep_schedule(self, sequence: ControlSequence, start: RolloutStart | None = None) -> SleepSchedule:
        """When ``sequence``'s commanded motion first comes within ``optimiser.weld_clearance`` of each
        object (from ``start``'s object poses, if given), the objects sleeping until
        ``optimiser.weld_lookahead`` before (never with the reduced model off: ``AWAKE``)."""
        sto = self.scenario.optimiser
        if self._sweep is None:
            return AWAKE
        states = None if start is None else start.states
        return SleepSchedule(
            self._sweep.approach_times(sequence, sto.weld_clearance, states), sto.weld_lookahead
        )

    def simulate(self, sequence: ControlSequence, start: RolloutStart | None = None) -> RolloutSamples:
        """Roll ``sequence`` out (from ``start``), reading the state every sample period."""
        schedule = self.sleep_schedule(sequence, start)
        return sample_rollout(sequence, self.full.scenario.optimiser, self.full, schedule, start=start)

    def rollout(self, sequence: ControlSequence, start: RolloutStart | None = None) -> RolloutOutcome:
        """Simulate ``sequence`` (from ``start``) and cost it."""
        return timed_rollout(sequence, self.simulate, self.full, start)

    def verify(self, sequence: ControlSequence, start: RolloutStart | None = None) -> RolloutOutcome:
        """Simulate ``sequence`` (from ``start``) on the execution model (built on first use), every
        object awake, and cost it."""
        if self._execution is None:
            self._execution = RolloutWorld(self.scenario, execution=True)
        return self._execution.rollout(sequence, start)
