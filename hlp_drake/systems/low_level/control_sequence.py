"""``ControlSequence``: the optimiser's decision variable, robot positions at knots in time.

A sequence of ``n`` control steps holds ``n + 1`` knots of the robot's positions
(``RobotDescription.position_names``) at increasing times from 0, joined by straight lines (a
first-order hold, as the paper joins its keyframes). ``from_trajectory`` keeps every keyframe of a
piecewise trajectory and splits its segments into steps no longer than ``max_step``. The STO
family's control of a step is a planar velocity (x, y, heading): of a mobile base
(``with_base_velocity``), or of a fixed arm's tcp (``with_planar_velocity``: per knot a map from a
planar displacement to the joints', ``hlp_drake.systems.low_level.sto.planar_noise``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from itertools import pairwise

import numpy as np
from pydrake.trajectories import PiecewisePolynomial

BASE_COLUMNS = (0, 1, 2)
"""Columns of a knot holding a mobile base's x, y and yaw (its first three positions)."""


@dataclass(frozen=True)
class ControlSequence:
    """Knots (n + 1, positions) of the robot's positions at ``times`` (n + 1,), which start at 0 and increase."""

    times: np.ndarray
    knots: np.ndarray

    def __post_init__(self) -> None:
        times = np.array(self.times, dtype=float)
        knots = np.array(self.knots, dtype=float)
        if knots.ndim != 2 or len(knots) < 2 or times.shape != (len(knots),):
            raise ValueError(
                f"a control sequence needs >= 2 knots and one time per knot, got {knots.shape} and {times.shape}"
            )
        if not (np.all(np.isfinite(knots)) and np.all(np.isfinite(times))):
            raise ValueError("a control sequence's times and knots must be finite")
        if times[0] != 0.0 or np.any(np.diff(times) <= 0):
            raise ValueError("a control sequence's times must start at 0 and increase")
        times.setflags(write=False)
        knots.setflags(write=False)
        object.__setattr__(self, "times", times)
        object.__setattr__(self, "knots", knots)

    @property
    def num_steps(self) -> int:
        return len(self.knots) - 1

    @property
    def duration(self) -> float:
        return float(self.times[-1])

    @property
    def steps(self) -> np.ndarray:
        """(n,) duration of every step."""
        return np.diff(self.times)

    @classmethod
    def from_trajectory(cls, trajectory: PiecewisePolynomial, max_step: float) -> ControlSequence:
        """The knots of ``trajectory`` (a first-order hold), every segment split into equal steps of at
        most ``max_step`` s; the sequence starts at time 0."""
        breaks = np.array(trajectory.get_segment_times(), dtype=float)
        times = [breaks[0]]
        for a, b in pairwise(breaks):
            pieces = max(1, math.ceil((b - a) / max_step - 1e-9))
            times.extend(a + (b - a) * np.arange(1, pieces + 1) / pieces)
        times = np.array(times)
        knots = np.column_stack([trajectory.value(t) for t in times]).T
        return cls(times - times[0], knots)

    def to_trajectory(self) -> PiecewisePolynomial:
        """The first-order hold through the knots."""
        return PiecewisePolynomial.FirstOrderHold(self.times, self.knots.T)

    def with_base_velocity(self, velocity: np.ndarray) -> ControlSequence:
        """This sequence with the base's (vx, vy, yaw rate) of every step raised by ``velocity`` (n, 3).

        The change of each step is integrated: knot k moves by the sum of the first k offsets times
        their steps' durations, so the base path shifts smoothly and the first knot (the start) stays.
        """
        velocity = np.asarray(velocity, dtype=float)
        if velocity.shape != (self.num_steps, 3):
            raise ValueError(f"expected ({self.num_steps}, 3) base velocities, got {velocity.shape}")
        knots = self.knots.copy()
        knots[1:, BASE_COLUMNS] += np.cumsum(velocity * self.steps[:, None], axis=0)
        return ControlSequence(self.times, knots)

    def with_planar_velocity(self, velocity: np.ndarray, maps: np.ndarray) -> ControlSequence:
        """This sequence with a planar velocity (n, 3) added through ``maps`` (n + 1, positions, 3):
        knot k moves by ``maps[k]`` times the integrated displacement up to it (as
        ``with_base_velocity`` integrates; the first knot stays)."""
        velocity = np.asarray(velocity, dtype=float)
        if velocity.shape != (self.num_steps, 3) or maps.shape != (*self.knots.shape, 3):
            raise ValueError(
                f"expected ({self.num_steps}, 3) velocities and {(*self.knots.shape, 3)} maps, got "
                f"{velocity.shape} and {maps.shape}"
            )
        displacement = np.cumsum(velocity * self.steps[:, None], axis=0)
        knots = self.knots.copy()
        knots[1:] += np.einsum("kij,kj->ki", maps[1:], displacement)
        return ControlSequence(self.times, knots)

    def joint_velocities(self) -> np.ndarray:
        """(n, positions) velocity of every position over each step."""
        return np.diff(self.knots, axis=0) / self.steps[:, None]

    def effort(self) -> float:
        """Integral of the squared commanded velocities: sum over steps of |v|^2 times the step."""
        return float(np.sum(self.joint_velocities() ** 2 * self.steps[:, None]))

    def followed_by(self, times: np.ndarray, knots: np.ndarray) -> PiecewisePolynomial:
        """The first-order hold through the knots, then through ``knots`` at ``times`` after the end
        (times > 0, increasing; e.g. the grasp and lift)."""
        all_times = np.concatenate([self.times, self.duration + np.asarray(times, dtype=float)])
        return PiecewisePolynomial.FirstOrderHold(all_times, np.vstack([self.knots, knots]).T)
