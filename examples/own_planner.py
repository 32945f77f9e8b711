"""Your own low-level planner: register it, with no edit under ``hlp_drake/``, and run it.

    python examples/own_planner.py --kind gen1 --seed 4

The planner here, ``smooth``, joins the initialiser's keyframes with a shape-preserving cubic
(Drake's ``PiecewisePolynomial.CubicShapePreserving``) sampled every ``step`` s and accepts it,
noting the objects it touches that the plan does not push (in the collision world of the kinematic
planners). A planner is its settings (a frozen ``LowLevelConfig`` whose ``kind`` is its name) and a
class with ``plan`` and ``as_commanded``; one ``register_low_level`` line names it. Any
``run_scene`` flag works after the script's name; ``--low-level smooth`` is added.
"""

from __future__ import annotations

import sys
from dataclasses import dataclass
from typing import Literal

import numpy as np
from pydrake.trajectories import PiecewisePolynomial

from hlp_drake.commands import command_main
from hlp_drake.commands.parsing import run_cli
from hlp_drake.systems.low_level.control_sequence import ControlSequence
from hlp_drake.systems.low_level.kinematic.waypoints import allowed_objects, sub_goals
from hlp_drake.systems.low_level.kinematic.world import KinematicWorld
from hlp_drake.systems.low_level.protocol import LowLevelConfig, LowLevelContext, LowLevelProblem
from hlp_drake.systems.low_level.registry import LowLevelEntry, register_low_level
from hlp_drake.systems.low_level.result import LowLevelResult


@dataclass(frozen=True)
class SmoothConfig(LowLevelConfig):
    """``smooth``'s settings: its control step, s."""

    kind: Literal["smooth"] = "smooth"
    step: float = 0.1


class Smooth:
    """A shape-preserving cubic through the initialiser's keyframes; what it touches is noted."""

    kind = "smooth"

    def __init__(self, config: SmoothConfig, context: LowLevelContext) -> None:
        self.config, self.model = config, context.model

    def as_commanded(self, trajectory: PiecewisePolynomial) -> ControlSequence:
        return ControlSequence.from_trajectory(trajectory, self.config.step)

    def plan(self, problem: LowLevelProblem) -> LowLevelResult:
        times = np.array(problem.initial.get_segment_times())
        cubic = PiecewisePolynomial.CubicShapePreserving(times, sub_goals(problem.initial).T, True)
        sequence = self.as_commanded(cubic)
        world = KinematicWorld(problem.scene, self.model, allowed_objects(problem.scene, problem.keyframes))
        touched = sorted({name for q in sequence.knots[:-1] for name, _ in world.contacts(q)})
        notes = (f"touches {', '.join(touched)}, which the plan does not push",) if touched else ()
        return LowLevelResult(sequence, None, True, None, low_level=self.kind, notes=notes)


register_low_level(LowLevelEntry("smooth", SmoothConfig, Smooth, "a cubic through the keyframes"))

if __name__ == "__main__":
    sys.exit(run_cli(command_main("run-scene"), ["--low-level", "smooth", *sys.argv[1:]]))
