"""How an execution commands the robot: open loop (a ``TrajectorySource``) or closed loop (a
``RecedingHorizonController``), behind one interface the execution's reach and grasp use."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from hlp_drake.systems.control_sequence import ControlSequence

if TYPE_CHECKING:
    from pydrake.systems.framework import Context
    from pydrake.systems.primitives import TrajectorySource

    from hlp_drake.systems.receding_horizon import RecedingHorizonController


class OpenLoopCommand:
    """``sequence`` played from time 0 by ``source``."""

    def __init__(self, source: TrajectorySource, sequence: ControlSequence) -> None:
        self._source, self._sequence = source, sequence

    def end(self, root_context: Context) -> float:
        """When the commanded reach ends, s of simulated time."""
        return self._sequence.duration

    def final(self, root_context: Context) -> np.ndarray:
        """The reach's last knot (11 positions)."""
        return self._sequence.knots[-1]

    def then(self, root_context: Context, t0: float, times: np.ndarray, knots: np.ndarray) -> None:
        """After holding the final knot, go through ``knots`` at ``t0 + times`` (e.g. the grasp)."""
        offset = t0 - self._sequence.duration
        self._source.UpdateTrajectory(
            self._sequence.followed_by(
                np.concatenate([[offset], offset + times]), np.vstack([self.final(root_context), knots])
            )
        )


class ClosedLoopCommand:
    """The sequence ``controller`` commands (re-optimised as the execution goes)."""

    def __init__(self, controller: RecedingHorizonController) -> None:
        self._controller = controller

    def end(self, root_context: Context) -> float:
        record = self._controller.record(root_context)
        return record.t0 + record.sequence.duration

    def final(self, root_context: Context) -> np.ndarray:
        return self._controller.record(root_context).sequence.knots[-1]

    def then(self, root_context: Context, t0: float, times: np.ndarray, knots: np.ndarray) -> None:
        sequence = ControlSequence(
            np.concatenate([[0.0], times]), np.vstack([self.final(root_context), knots])
        )
        self._controller.command(root_context, sequence, t0)


__all__ = ["ClosedLoopCommand", "OpenLoopCommand"]
