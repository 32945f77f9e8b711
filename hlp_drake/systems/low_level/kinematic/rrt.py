"""``RrtPlanner``: OMPL's RRT-Connect as a low-level planner (the registry's ``rrt``).

Each leg between two sub-goals that a straight motion cannot take is planned by RRT-Connect in the
robot's configuration space (the fingers held at the leg's wider grip), within the joint limits
and a box around the leg's ends (``margin``), every state and motion checked by Drake's
``SceneGraphCollisionChecker``; its path is then shortcut (each knot joined to the farthest later
one a straight motion reaches). Its budget counts RRT-Connect's iterations, over all legs.

OMPL seeds its samplers from one generator per process; a plan restarts it and draws ``seed``
seeds first, so the same seed gives the same path in any process (``seeded``).
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from dataclasses import dataclass
from functools import cache
from typing import Annotated, Literal

import numpy as np

from hlp_drake.config.ranges import MAX_SEED, Count, Positive
from hlp_drake.errors import HlpError
from hlp_drake.systems.low_level.kinematic.planner import KinematicConfig, KinematicPlanner, Leg
from hlp_drake.systems.low_level.kinematic.world import KinematicWorld
from hlp_drake.systems.low_level.protocol import LowLevelContext, LowLevelProblem
from hlp_drake.systems.low_level.result import LowLevelResult

PROCESS_SEED = 1
"""The seed OMPL's generator of seeds starts from (set before any of its random numbers)."""


@dataclass(frozen=True)
class RrtConfig(KinematicConfig):
    """Settings of ``rrt`` (and ``KinematicConfig``'s).

    Attributes:
        kind: "rrt".
        iterations: RRT-Connect's iterations for the whole plan (every leg's count).
        range: the longest step of a tree's extension (0: OMPL's default), in the positions' units.
        margin: how far beyond its ends' box a leg may go, rad (m for a mobile base's x and y).
        shortcut: shortcut the path.
        seed: which of OMPL's seed streams the plan uses.
    """

    kind: Literal["rrt"] = "rrt"
    iterations: Annotated[int, Count(1, 1_000_000)] = 5_000
    range: Annotated[float, Positive(0.0, 10.0, zero_ok=True)] = 0.5
    margin: Annotated[float, Positive(0.0, 6.3, zero_ok=True)] = 0.6
    shortcut: bool = True
    seed: Annotated[int, Count(0, MAX_SEED)] = 0


def _ompl():
    """OMPL's ``base``, ``geometric`` and ``util`` modules (its generator seeded at first import).

    Raises:
        HlpError: the ``ompl`` package is not installed.
    """
    try:
        from ompl import base, geometric, util
    except ImportError:
        raise HlpError(
            "the low-level planner rrt needs the ompl package (pip install ompl), which is not installed"
        ) from None
    if not getattr(_ompl, "seeded", False):
        util.RNG.setSeed(PROCESS_SEED)
        _ompl.seeded = True
    return base, geometric, util


@contextlib.contextmanager
def seeded(seed: int) -> Iterator[None]:
    """OMPL's generator of seeds restarted, ``seed`` seeds drawn, and its messages silenced."""
    _, _, util = _ompl()
    level = util.getLogLevel()
    util.setLogLevel(util.LOG_NONE)
    try:
        util.RNG.setSeed(PROCESS_SEED)  # restarts the generator (OMPL logs that as an error)
        for _ in range(seed):
            util.RNG()
        yield
    finally:
        util.setLogLevel(level)


class RrtPlanner(KinematicPlanner):
    """``rrt`` (see the module's docstring)."""

    kind = "rrt"
    config: RrtConfig

    def __init__(self, config: RrtConfig, context: LowLevelContext) -> None:
        _ompl()  # refuse now if OMPL is missing
        super().__init__(config, context)

    @property
    def budget(self) -> int:
        return self.config.iterations

    def plan(self, problem: LowLevelProblem) -> LowLevelResult:
        with seeded(self.config.seed):
            return super().plan(problem)

    def segment(self, world: KinematicWorld, start: np.ndarray, goal: np.ndarray, budget: int) -> Leg:
        base, geometric, _ = _ompl()
        config = self.config
        columns = world.planned_columns
        lower, upper, _ = world.limits
        low = np.maximum(lower[columns], np.minimum(start[columns], goal[columns]) - config.margin)
        high = np.minimum(upper[columns], np.maximum(start[columns], goal[columns]) + config.margin)
        high = np.maximum(high, low + 1e-6)
        space = base.RealVectorStateSpace(len(columns))
        bounds = base.RealVectorBounds(len(columns))
        for i, (lo, hi) in enumerate(zip(low, high)):
            bounds.setLow(i, float(lo))
            bounds.setHigh(i, float(hi))
        space.setBounds(bounds)
        setup = geometric.SimpleSetup(space)
        q = start.copy()

        def positions(state) -> np.ndarray:
            q[columns] = [state[i] for i in range(len(columns))]
            return q.copy()

        setup.setStateValidityChecker(lambda state: world.free(positions(state)))
        information = setup.getSpaceInformation()
        validator = _edge_validator_class()(information, world, positions)
        information.setMotionValidator(validator)
        ends = []
        for values in (start[columns], goal[columns]):
            state = space.allocState()
            for i, value in enumerate(values):
                state[i] = float(value)
            ends.append(state)
        setup.setStartAndGoalStates(*ends)
        planner = geometric.RRTConnect(information)
        if config.range > 0:
            planner.setRange(config.range)
        setup.setPlanner(planner)
        count = 0

        def stop() -> bool:
            nonlocal count
            count += 1
            return count > budget

        setup.solve(base.PlannerTerminationCondition(stop))
        del validator  # OMPL's space information holds it until the setup goes
        iterations = min(count, budget)
        if not setup.haveExactSolutionPath():
            return Leg(None, iterations)
        found = setup.getSolutionPath()
        path = np.array([positions(found.getState(i)) for i in range(found.getStateCount())])
        path[0], path[-1] = start, goal
        return Leg(shortcut(world, path) if config.shortcut else path, iterations)


@cache
def _edge_validator_class():
    base, _, _ = _ompl()

    class EdgeValidator(base.MotionValidator):
        """A motion is valid when Drake's checker finds the straight one free (one call per motion,
        checked in C++ at the world's ``edge_step``)."""

        def __init__(self, information, world: KinematicWorld, positions) -> None:
            super().__init__(information)
            self._world, self._positions = world, positions

        def checkMotion(self, a, b, *last_valid) -> bool:
            return self._world.edge_free(self._positions(a), self._positions(b))

    return EdgeValidator


def shortcut(world: KinematicWorld, path: np.ndarray, passes: int = 12) -> np.ndarray:
    """``path`` with every knot joined to the farthest later knot a free straight motion reaches, then
    pulled taut: each inner knot moved, ``passes`` times, half way to the straight line between the
    path's ends where both its motions stay free (a detour as small as the obstacles allow)."""
    kept, i = [path[0]], 0
    while i < len(path) - 1:
        j = len(path) - 1
        while j > i + 1 and not world.edge_free(path[i], path[j]):
            j -= 1
        kept.append(path[j])
        i = j
    taut = np.array(kept)
    if len(taut) < 3:
        return taut
    share = np.cumsum(np.r_[0.0, np.linalg.norm(np.diff(taut, axis=0), axis=1)])
    line = taut[0] + (share / share[-1])[:, None] * (taut[-1] - taut[0])
    for _ in range(passes):
        for k in range(1, len(taut) - 1):
            moved = 0.5 * (taut[k] + line[k])
            if world.edge_free(taut[k - 1], moved) and world.edge_free(moved, taut[k + 1]):
                taut[k] = moved
    return taut


__all__ = ["RrtConfig", "RrtPlanner", "seeded", "shortcut"]
