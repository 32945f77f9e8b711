"""``TrajoptPlanner``: Drake's ``KinematicTrajectoryOptimization`` as a low-level planner (the
registry's ``trajopt``).

Each leg between two sub-goals that a straight motion cannot take is a B-spline in the robot's
configuration space from one to the other, at rest at both ends, within the joints' position,
velocity and acceleration limits, kept ``min_distance`` from every obstacle at ``samples`` points
(``MinimumDistanceLowerBoundConstraint``), and as short and quick as it can be; SNOPT solves it from
the straight line. The path is then checked between its samples by the collision checker.
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import pairwise
from typing import Annotated, Literal

import numpy as np
from pydrake.multibody.inverse_kinematics import MinimumDistanceLowerBoundConstraint
from pydrake.planning import KinematicTrajectoryOptimization
from pydrake.solvers import SnoptSolver, Solve, SolverOptions
from pydrake.trajectories import BsplineTrajectory

from hlp_drake.config.ranges import Count, Positive
from hlp_drake.systems.low_level.kinematic.planner import KinematicConfig, KinematicPlanner, Leg
from hlp_drake.systems.low_level.kinematic.world import KinematicWorld


@dataclass(frozen=True)
class TrajoptConfig(KinematicConfig):
    """Settings of ``trajopt`` (and ``KinematicConfig``'s).

    Attributes:
        kind: "trajopt".
        control_points: the B-spline's control points per leg.
        samples: points per leg where the distance to the obstacles is constrained.
        min_distance: the least distance kept from the obstacles at the samples, m (less where a
            sub-goal itself is nearer).
        acceleration_time: the acceleration limit is the velocity limit over this time, s.
        iterations: SNOPT's major iterations per solve.
        knots: knots of the solved B-spline kept per leg (the commanded motion's).
    """

    kind: Literal["trajopt"] = "trajopt"
    control_points: Annotated[int, Count(4, 60)] = 10
    samples: Annotated[int, Count(2, 200)] = 25
    min_distance: Annotated[float, Positive(0.0, 0.1, zero_ok=True)] = 0.005
    acceleration_time: Annotated[float, Positive(0.01, 10.0)] = 0.5
    iterations: Annotated[int, Count(1, 10_000)] = 300
    knots: Annotated[int, Count(2, 500)] = 30


class TrajoptPlanner(KinematicPlanner):
    """``trajopt`` (see the module's docstring): its iterations count SNOPT solves (one per leg
    that is not straight), each within ``config.iterations`` major iterations."""

    kind = "trajopt"
    config: TrajoptConfig

    @property
    def budget(self) -> int:
        return 1_000_000  # solves are bounded per leg, by SNOPT's iterations

    def noun(self, iterations: int) -> str:
        return f"trajopt found no path in {iterations} solves"

    def segment(self, world: KinematicWorld, start: np.ndarray, goal: np.ndarray, budget: int) -> Leg:
        config = self.config
        lower, upper, velocity = world.limits
        fingers = list(world.description.finger_columns)
        lower, upper = lower.copy(), upper.copy()
        lower[fingers] = upper[fingers] = start[fingers]
        optimisation = KinematicTrajectoryOptimization(len(start), config.control_points)
        program = optimisation.get_mutable_prog()
        optimisation.AddDurationCost(1.0)
        optimisation.AddPathLengthCost(1.0)
        optimisation.AddPositionBounds(lower, upper)
        optimisation.AddVelocityBounds(-velocity, velocity)
        acceleration = velocity / config.acceleration_time
        optimisation.AddAccelerationBounds(-acceleration, acceleration)
        optimisation.AddDurationConstraint(0.05, 60.0)
        rest = np.zeros(len(start))
        for s, q in ((0.0, start), (1.0, goal)):
            optimisation.AddPathPositionConstraint(q, q, s)
            optimisation.AddPathVelocityConstraint(rest, rest, s)
        bound = max(0.0, min(config.min_distance, world.clearance(start), world.clearance(goal)) - 1e-4)
        distance = MinimumDistanceLowerBoundConstraint(
            plant=world.plant,
            bound=bound,
            plant_context=world.plant_context,
            influence_distance_offset=0.05,
        )
        for s in np.linspace(0.0, 1.0, config.samples):
            optimisation.AddPathPositionConstraint(distance, s)
        guess = np.linspace(start, goal, config.control_points).T
        optimisation.SetInitialGuess(BsplineTrajectory(optimisation.basis(), list(guess.T[:, :, None])))
        options = SolverOptions()
        options.SetOption(SnoptSolver.id(), "Major iterations limit", config.iterations)
        result = Solve(program, solver_options=options)
        if not result.is_success():
            return Leg(
                None,
                1,
                f"trajopt found no path ({result.get_solver_id().name()}: {result.get_solution_result().name})",
            )
        trajectory = optimisation.ReconstructTrajectory(result)
        times = np.linspace(trajectory.start_time(), trajectory.end_time(), config.knots)
        path = np.array([trajectory.value(t).ravel() for t in times])
        path[0], path[-1] = start, goal
        for a, b in pairwise(path):
            if not world.edge_free(a, b):
                return Leg(None, 1, "trajopt's path touches an obstacle between its distance samples")
        return Leg(path, 1, durations=np.diff(times))


__all__ = ["TrajoptConfig", "TrajoptPlanner"]
