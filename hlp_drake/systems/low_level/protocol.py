"""What every low-level planner is: its settings (``LowLevelConfig``), what it is given
(``LowLevelProblem``, ``LowLevelContext``) and what it does (``LowLevelPlanner``).

A low-level planner turns the initialiser's start (the keyframes of the human-like plan or of the
straight line, and the joint trajectory through them) into the robot's commanded motion, a
``ControlSequence``, and says how it went in a ``LowLevelResult``
(``hlp_drake.systems.low_level.result``). Its Drake block is ``LowLevelPlannerSystem``
(``hlp_drake.systems.low_level.system``); the registry (``hlp_drake.systems.low_level.registry``)
names every planner, its settings and how it is made. Adding a planner is one module (its settings
and its planner) and one registry line.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, ClassVar, Protocol

from hlp_drake.systems.world.success import SuccessConfig

if TYPE_CHECKING:
    from pydrake.trajectories import PiecewisePolynomial

    from hlp_drake.scene.model import Scene
    from hlp_drake.systems.low_level.control_sequence import ControlSequence
    from hlp_drake.systems.low_level.outcome import RolloutStart
    from hlp_drake.systems.low_level.result import LowLevelResult
    from hlp_drake.systems.low_level.sto.pool import RolloutPool
    from hlp_drake.systems.planning.keyframes import Keyframes
    from hlp_drake.systems.world.model import WorldModel


@dataclass(frozen=True)
class LowLevelConfig:
    """The settings of a low-level planner: the base of each planner's own, which names the planner
    in ``kind`` (its registry name). A scenario's ``planner.low_level`` holds one of them, picked
    by ``kind`` (a tagged union: ``hlp_drake.config.typed_yaml``)::

        planner:
          low_level: {kind: sto, samples: 8}
    """

    kind: str = ""

    TAG: ClassVar[str] = "kind"
    """The field that names the variant (``hlp_drake.config.typed_yaml``'s tagged unions)."""
    NOUN: ClassVar[str] = "low-level planner"
    """What a variant is called in messages."""

    @classmethod
    def variants(cls) -> Mapping[str, type[LowLevelConfig]]:
        """Every registered planner's settings class, by name."""
        from hlp_drake.systems.low_level.registry import LOW_LEVEL_PLANNERS

        return {name: entry.config_class() for name, entry in LOW_LEVEL_PLANNERS.items()}

    def problems(self, where: str) -> list[str]:
        """Rules across the fields (none here; a planner's settings may add theirs)."""
        return []


@dataclass(frozen=True)
class LowLevelContext:
    """What a low-level planner may use besides its settings, given when it is made.

    Attributes:
        model: the world model it plans in (a planner that simulates rolls out in it).
        pool: the rollout workers (only for planners that roll out: ``LowLevelEntry.rolls_out``).
        perceived: whether the scene it plans on was perceived by cameras (not the true one).
        success: the success test its motion will be judged by (a planner that simulates applies
            it to its own simulations).
    """

    model: WorldModel
    pool: RolloutPool | None = None
    perceived: bool = False
    success: SuccessConfig = field(default_factory=SuccessConfig)


@dataclass(frozen=True)
class LowLevelProblem:
    """One planning problem.

    Attributes:
        scene: the scene as the planners see it.
        keyframes: the initialiser's keyframes (IK): where to go, and (``keypoints``) what to push.
        initial: the joint trajectory through them (``KeypointIk``'s ``trajectory``).
        alternatives: the initialiser's next candidates' trajectories, best first; called only if
            the planner asks for them.
    """

    scene: Scene
    keyframes: Keyframes | None
    initial: PiecewisePolynomial
    alternatives: Callable[[], Sequence[PiecewisePolynomial]] = tuple


@dataclass(frozen=True)
class ReplanProblem:
    """One re-plan from a measured state (the closed loop's).

    Attributes:
        scene: the scene as observed now.
        initial: the sequence to improve (the warm start: the rest of the commanded one).
        start: the measured state to plan from.
        iterations: the re-plan's iteration budget.
        rollouts: its rollout budget.
        attempt: which re-plan this is (0, 1, ...): a seed for its random choices.
        alternatives: other sequences to try (the first) if ``initial`` fails; None: none.
    """

    scene: Scene
    initial: ControlSequence
    start: RolloutStart
    iterations: int
    rollouts: int
    attempt: int
    alternatives: Callable[[], Sequence[ControlSequence]] | None = None


class LowLevelPlanner(Protocol):
    """A low-level planner: made by its registry entry from its settings and a ``LowLevelContext``."""

    kind: str
    """Its registry name."""

    def plan(self, problem: LowLevelProblem) -> LowLevelResult:
        """The commanded motion for ``problem``, and how it went; never raises for a bad scene."""
        ...

    def as_commanded(self, trajectory: PiecewisePolynomial) -> ControlSequence:
        """``trajectory`` as this planner commands a motion (e.g. sampled at its control steps): what
        the execution plays when there is nothing to plan (no plan, IK failed)."""
        ...


class ReplanningPlanner(LowLevelPlanner, Protocol):
    """A low-level planner that re-plans from a measured state (its registry entry ``replans``):
    what the closed loop (``RecedingHorizonController``) runs."""

    def replan(self, problem: ReplanProblem) -> LowLevelResult:
        """The commanded motion from ``problem``'s measured state on, within its budget."""
        ...


__all__ = [
    "LowLevelConfig",
    "LowLevelContext",
    "LowLevelPlanner",
    "LowLevelProblem",
    "ReplanProblem",
    "ReplanningPlanner",
]
