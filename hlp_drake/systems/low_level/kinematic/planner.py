"""``KinematicPlanner``: what every kinematic low-level planner does; ``KinematicConfig``: the
settings they share.

A kinematic planner plans a joint path through the initialiser's sub-goals (``sub_goals``) that
touches no obstacle: the table, and every object but those the human-like plan pushes
(``allowed_objects``; the straight line pushes nothing). The initialiser's own sub-goals may touch
what they touch, on their legs only: the target on the last leg, and an object a sub-goal's
configuration touches on the legs to and from it (the result's ``notes`` say which); a sub-goal
between the start and the goal that touches the table is left out. Each leg between two
sub-goals is straight where that is free, else the planner's own (``segment``). When no free path
exists (the goal itself touches an obstacle, or a leg finds none), the ``fallback`` plans again
with every object allowed, and the result says so in ``fallback``.
The path is timed (``PathTiming``); the pushes happen in the world that executes it.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Annotated

import numpy as np

from hlp_drake.config.ranges import Positive
from hlp_drake.systems.low_level.control_sequence import ControlSequence
from hlp_drake.systems.low_level.kinematic.timing import PathTiming, timed
from hlp_drake.systems.low_level.kinematic.waypoints import allowed_objects, sub_goals
from hlp_drake.systems.low_level.kinematic.world import KinematicWorld
from hlp_drake.systems.low_level.protocol import LowLevelConfig, LowLevelContext, LowLevelProblem
from hlp_drake.systems.low_level.result import LowLevelResult, held, unplanned

if TYPE_CHECKING:
    from pydrake.trajectories import PiecewisePolynomial

    from hlp_drake.scene.model import Scene


@dataclass(frozen=True)
class KinematicConfig(LowLevelConfig):
    """The settings every kinematic planner has.

    Attributes:
        edge_step: the step at which a straight motion is checked for collisions, rad (m for a
            mobile base's x and y).
        padding: clearance kept from the obstacles by the collision checker, m.
        fallback: with no collision-free path, plan again with every object allowed (stated in the
            result's ``fallback``); False: the run fails.
        timing: how the path is timed.
    """

    edge_step: Annotated[float, Positive(0.001, 0.5)] = 0.02
    padding: Annotated[float, Positive(0.0, 0.1, zero_ok=True)] = 0.0
    fallback: bool = True
    timing: PathTiming = field(default_factory=PathTiming)


@dataclass
class Leg:
    """A planned leg: its knots (k, positions) from one sub-goal to the next, both included (None:
    none found, ``reason`` says why), its iterations and its knots' planned durations (k - 1,), if any."""

    path: np.ndarray | None
    iterations: int
    reason: str = ""
    durations: np.ndarray | None = None


@dataclass
class _Attempt:
    path: np.ndarray | None
    durations: np.ndarray | None
    iterations: int
    reason: str
    notes: list[str]
    world: KinematicWorld


class KinematicPlanner:
    """The shared part of a kinematic planner (see the module's docstring); a planner gives ``kind``
    and ``segment``."""

    kind = ""

    def __init__(self, config: KinematicConfig, context: LowLevelContext) -> None:
        self.config, self.model = config, context.model

    def as_commanded(self, trajectory: PiecewisePolynomial) -> ControlSequence:
        """``trajectory``'s knots as they are."""
        return ControlSequence.from_trajectory(trajectory, max_step=np.inf)

    def segment(self, world: KinematicWorld, start: np.ndarray, goal: np.ndarray, budget: int) -> Leg:
        """A collision-free leg from ``start`` to ``goal`` in ``world`` within ``budget`` iterations."""
        raise NotImplementedError

    def noun(self, iterations: int) -> str:
        """What the planner did, for a failure's reason."""
        return f"{self.kind} found no path in {iterations} iterations"

    def plan(self, problem: LowLevelProblem) -> LowLevelResult:
        started = time.perf_counter()
        if problem.initial.get_number_of_segments() == 0:
            start = None if problem.keyframes is None else problem.keyframes.start
            return unplanned(held(start), "no initial trajectory", self.kind)
        goals = sub_goals(problem.initial)
        scene = problem.scene
        attempt = self._attempt(scene, goals, allowed_objects(scene, problem.keyframes), self.budget)
        iterations, fallback = attempt.iterations, ""
        if attempt.path is None and self.config.fallback:
            everything = {scene.target.name, *(o.name for o in scene.obstacles)}
            fallback = f"contact allowed with every object ({attempt.reason})"
            attempt = self._attempt(scene, goals, everything, max(1, self.budget - iterations))
            iterations += attempt.iterations
        seconds = time.perf_counter() - started
        if attempt.path is None:
            return LowLevelResult(
                self.as_commanded(problem.initial),
                None,
                False,
                attempt.reason,
                iterations=iterations,
                optimise_s=seconds,
                low_level=self.kind,
                fallback=fallback,
                notes=tuple(attempt.notes),
            )
        sequence = timed(attempt.world, attempt.path, self.config.timing, attempt.durations)
        return LowLevelResult(
            sequence,
            None,
            True,
            None,
            iterations=iterations,
            optimise_s=time.perf_counter() - started,
            low_level=self.kind,
            fallback=fallback,
            notes=tuple(attempt.notes),
        )

    @property
    def budget(self) -> int:
        """The iterations a plan may use in all (its legs share them)."""
        raise NotImplementedError

    def _attempt(self, scene: Scene, goals: np.ndarray, allowed, budget: int) -> _Attempt:
        """A path through ``goals`` touching nothing but ``allowed`` (and its iterations), or why not."""
        config = self.config
        world = KinematicWorld(scene, self.model, allowed, edge_step=config.edge_step, padding=config.padding)
        notes: list[str] = []

        def failed(reason: str, iterations: int = 0) -> _Attempt:
            return _Attempt(None, None, iterations, reason, notes, world)

        objects = {scene.target.name, *(o.name for o in scene.obstacles)}
        last = len(goals) - 1
        kept, touches = [], []
        for index, q in enumerate(goals):
            reach = {scene.target.name} if index == last else set()
            world.touching(reach)
            contacts = world.contacts(q)
            names = {name for name, _ in contacts}
            if names <= objects:
                world.touching(reach | names)
            if names <= objects and world.free(q):
                if names:
                    notes.append(
                        f"sub-goal {index} of {last} touches {_named(contacts)}: allowed on its legs"
                    )
                kept.append(q)
                touches.append(reach | names)
            elif index in (0, last):
                return failed(f"the {'start' if index == 0 else 'goal'} touches {_named(contacts)}")
            else:
                notes.append(f"sub-goal {index} of {last} left out: it touches {_named(contacts)}")
        fingers = list(world.description.finger_columns)
        path, durations, iterations = [kept[0]], [], 0
        for k in range(1, len(kept)):
            world.touching(touches[k - 1] | touches[k])
            goal = kept[k]
            a, b = _gripped(world, path[-1], goal, fingers)
            if a is None:
                return failed(f"sub-goal {k} touches {_named(world.contacts(goal))} on its leg", iterations)
            if world.edge_free(a, b):
                leg = Leg(np.array([a, b]), 0)
            else:
                leg = self.segment(world, a, b, max(0, budget - iterations))
                iterations += leg.iterations
                if leg.path is None:
                    return failed(leg.reason or self.noun(iterations), iterations)
            knots = np.array(leg.path[1:], dtype=float)
            share = np.linspace(0.0, 1.0, len(knots) + 1)[1:, None]
            knots[:, fingers] = path[-1][fingers] + share * (goal[fingers] - path[-1][fingers])
            path.extend(knots)
            durations.extend(np.zeros(len(knots)) if leg.durations is None else leg.durations)
        return _Attempt(np.array(path), np.array(durations), iterations, "", notes, world)


def _gripped(world: KinematicWorld, start: np.ndarray, goal: np.ndarray, fingers: list[int]):
    """``start`` and ``goal`` with the fingers at the leg's grip: the wider of their two openings, or
    the narrower where the wider touches an obstacle; (None, None) if neither is free at both ends."""
    for grip in (np.maximum, np.minimum):
        a, b = start.copy(), goal.copy()
        a[fingers] = b[fingers] = grip(start[fingers], goal[fingers])
        if world.free(a) and world.free(b):
            return a, b
    return None, None


def _named(contacts: list[tuple[str, float]]) -> str:
    if not contacts:
        return "an obstacle within the padding"
    return ", ".join(f"{name} ({-depth * 100:.1f} cm deep)" for name, depth in contacts)


__all__ = ["KinematicConfig", "KinematicPlanner", "Leg"]
