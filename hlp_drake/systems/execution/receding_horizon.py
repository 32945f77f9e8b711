"""``RecedingHorizonController``: closed-loop execution, a low-level planner that re-plans (the STO)
re-run on the measured state.

Input ports:
    ``state``: the plant's whole state (the world's ``state`` output): the robot's state, and the
        measured objects' (``objects``; none when the scene is perceived by cameras).
    ``scene`` (abstract ``Scene``): the observed scene, from the diagram's scene source (``SceneFromPlant``
        on the plant's poses, or ``ScenePerception`` on the cameras: then the objects are known only
        from it), read at the start and at every re-plan.
    ``perception`` (abstract ``Perception``, optional): the scene source's frame, for why a scene
        without a target was observed (``ScenePerception``'s ``perception`` output).
    ``initial`` (abstract ``LowLevelResult``, e.g. the planning diagram's ``optimisation``): the
        open-loop plan, read once when the simulation is initialised.

Output port:
    ``desired_trajectory_state``: the robot's commanded positions then their velocities now (zero
        velocities once the sequence has ended); ``connect_robot_command`` feeds it to the world.

Every ``closed_loop.replan_period`` s of simulated time while its sequence lasts (a periodic
unrestricted update: the simulation waits for it), the controller reads the measured state and the
observed scene, cuts its commanded sequence there (the warm start: its remainder, starting where the
robot is commanded now) and re-plans from the measured state (``ReplanningPlanner.replan`` of a
``ReplanProblem``, e.g. the STO's; ``RolloutStart``: objects not measured start at rest where the
observed scene has them) with the budget of
``closed_loop.iterations`` and ``closed_loop.rollouts`` (and within ``closed_loop.max_rollouts`` in
all: once those are spent, no more re-optimisation); the result's sequence is commanded from then
on (the optimiser's acceptance is monotone: the remainder unless a candidate is cheaper or passes;
re-optimisations do not verify on the execution model: the execution itself goes on from there).
While the initial sequence passed its verification on the execution model and every observed object
is within ``closed_loop.track_distance`` of where that verification had it (the plan is on track:
the world is the model it was verified on), the controller keeps it and does not re-optimise; from
the first re-plan off track on it re-optimises at every period. When an observed object is farther
than ``closed_loop.replan_distance`` from where the current sequence's rollout put it (objects
paired by position), and an ``initialiser`` is given, its sequence for the observed scene from the
robot's measured state (e.g. the planner's) is optimised instead, the remainder its alternative. An observed scene without a target (a failed frame) is not used: the
last good one is kept and the reason counted. The commanded sequence, the scene its rollout
predicted and the counts live in the context's abstract state (``ControllerRecord``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.systems.framework import Context, LeafSystem, State

from hlp_drake.scene.model import Scene
from hlp_drake.systems.low_level.control_sequence import ControlSequence
from hlp_drake.systems.low_level.outcome import Prediction, RolloutStart
from hlp_drake.systems.low_level.protocol import ReplanProblem
from hlp_drake.systems.low_level.result import EMPTY_RESULT, LowLevelResult
from hlp_drake.systems.perception.accuracy import largest_displacement
from hlp_drake.systems.perception.perception import Perception
from hlp_drake.systems.world.scene_source import declare_scene_input_port, scene_input

if TYPE_CHECKING:
    from pydrake.multibody.plant import MultibodyPlant

    from hlp_drake.systems.execution.closed_loop import ClosedLoopConfig
    from hlp_drake.systems.low_level.protocol import ReplanningPlanner

MIN_REMAINDER = 1.0e-3
"""A sequence with less than this left (s) is not re-optimised."""
Initialiser = Callable[[Scene, np.ndarray], "ControlSequence | None"]
"""A fresh initial sequence for an observed scene from the robot's measured state (positions, velocities)."""


RECORDED = (
    "replans",
    "on_track",
    "rollouts",
    "initialised",
    "changed",
    "reason",
    "observations",
    "observation_failures",
    "observation_reason",
    "budget_spent",
)
"""What a controller's record says in JSON (``ControllerRecord.to_dict``)."""


@dataclass(frozen=True)
class ControllerRecord:
    """The controller's state: the commanded ``sequence`` (started at simulated time ``t0``), the
    prediction of its last rollout and the ``scene`` that rollout was on, the verified initial
    sequence's prediction on the execution model while the plan is on track (``track``; the
    sequence is then the initial one, from ``t0``), the last good observed scene, and what the re-optimisations and observations did
    (``on_track``: re-plans skipped on track)."""

    sequence: ControlSequence | None = None
    t0: float = 0.0
    prediction: Prediction | None = None
    replans: int = 0
    rollouts: int = 0
    initialised: int = 0
    changed: int = 0
    reason: str | None = None
    scene: Scene | None = None
    observed: Scene | None = None
    observations: int = 0
    observation_failures: int = 0
    observation_reason: str | None = None
    track: Prediction | None = None
    on_track: int = 0
    budget_spent: bool = False

    def to_dict(self) -> dict:
        """The counts and reasons as JSON-ready data (not the sequence, the predictions, the scenes)."""
        return {name: getattr(self, name) for name in RECORDED}


def remainder(sequence: ControlSequence, t: float) -> ControlSequence | None:
    """``sequence`` from ``t`` on, starting at time 0 at its value at ``t`` (None: less than
    ``MIN_REMAINDER`` left)."""
    if sequence.duration - t < MIN_REMAINDER:
        return None
    later = sequence.times > t + MIN_REMAINDER
    now = sequence.to_trajectory().value(t).ravel()
    return ControlSequence(
        np.concatenate([[0.0], sequence.times[later] - t]), np.vstack([now, sequence.knots[later]])
    )


class RecedingHorizonController(LeafSystem):
    """The receding-horizon controller (see the module's docstring for the ports and the behaviour).

    Args:
        plant: the world's plant (to split its state by model instance; not simulated here).
        planner: the low-level planner that re-plans (``ReplanningPlanner``, e.g. ``StoPlanner``).
        closed_loop: the controller's settings (a ``Scenario``'s ``closed_loop``).
        robot: the robot's model instance name.
        objects: the objects measured on ``state`` (none when the scene is perceived by cameras:
            the objects are then what the ``scene`` input shows).
        initialiser: a fresh initial sequence for the observed scene (``Initialiser``; None: none).
    """

    def __init__(
        self,
        plant: MultibodyPlant,
        *,
        planner: ReplanningPlanner,
        closed_loop: ClosedLoopConfig,
        robot: str,
        objects: tuple[str, ...] = (),
        initialiser: Initialiser | None = None,
    ) -> None:
        super().__init__()
        self._planner, self._closed, self._initialiser = planner, closed_loop, initialiser
        self._plant = plant
        self._robot_name = robot_name = robot
        names = [robot_name] + [name for name in objects if plant.HasModelInstanceNamed(name)]
        self._instances = {n: plant.GetModelInstanceByName(n) for n in names}
        self._state = self.DeclareVectorInputPort("state", plant.num_multibody_states())
        self._scene = declare_scene_input_port(self)
        self._perception = self.DeclareAbstractInputPort(
            "perception", AbstractValue.Make(Perception(None, "not perceived"))
        )
        self._initial = self.DeclareAbstractInputPort("initial", AbstractValue.Make(EMPTY_RESULT))
        self._record = self.DeclareAbstractState(AbstractValue.Make(ControllerRecord()))
        nq = plant.num_positions(self._instances[robot_name])
        self.DeclareVectorOutputPort(
            "desired_trajectory_state",
            2 * nq,
            self._calc_desired,
            {self.time_ticket(), self.abstract_state_ticket(self._record), self._state.ticket()},
        )
        self.DeclareInitializationUnrestrictedUpdateEvent(self._initialise)
        self.DeclarePeriodicUnrestrictedUpdateEvent(
            closed_loop.replan_period, closed_loop.replan_period, self._replan
        )

    def record(self, root_context: Context) -> ControllerRecord:
        """The controller's state in the diagram's ``root_context``."""
        return self.GetMyContextFromRoot(root_context).get_abstract_state(int(self._record)).get_value()

    def command(self, root_context: Context, sequence: ControlSequence, t0: float) -> None:
        """Command ``sequence`` from simulated time ``t0`` on, and stop re-optimising (e.g. the grasp)."""
        mine = self.GetMyMutableContextFromRoot(root_context)
        record = self.record(root_context)
        mine.get_mutable_abstract_state(int(self._record)).set_value(
            replace(record, sequence=sequence, t0=t0, prediction=None, reason="commanded")
        )

    def _states(self, context: Context) -> dict[str, np.ndarray]:
        x = self._state.Eval(context)
        plant = self._plant
        q, v = x[: plant.num_positions()], x[plant.num_positions() :]
        return {
            name: np.concatenate([plant.GetPositionsFromArray(i, q), plant.GetVelocitiesFromArray(i, v)])
            for name, i in self._instances.items()
        }

    def _observe(self, context: Context, record: ControllerRecord) -> ControllerRecord:
        """``record`` with the scene on the ``scene`` input observed (kept unless it has no target)."""
        scene = scene_input(self._scene, context)
        if scene.target is not None:
            return replace(record, observed=scene, observations=record.observations + 1)
        reason = "the observed scene has no target"
        if self._perception.HasValue(context):
            reason = self._perception.Eval(context).reason or reason
        return replace(
            record,
            observations=record.observations + 1,
            observation_failures=record.observation_failures + 1,
            observation_reason=reason,
        )

    def _initialise(self, context: Context, state: State) -> None:
        result: LowLevelResult = self._initial.Eval(context)
        prediction = None if result.outcome is None else result.outcome.prediction
        verified = None if result.outcome is None else result.outcome.verification
        track = verified.prediction if verified is not None and verified.success else None
        record = self._observe(context, ControllerRecord())
        state.get_mutable_abstract_state(int(self._record)).set_value(
            replace(
                record,
                sequence=result.sequence,
                t0=float(context.get_time()),
                prediction=prediction,
                scene=record.observed,
                track=track,
            )
        )

    def _replan(self, context: Context, state: State) -> None:
        record: ControllerRecord = context.get_abstract_state(int(self._record)).get_value()
        if record.sequence is None or record.reason == "commanded" or record.budget_spent:
            return
        left = self._closed.max_rollouts - record.rollouts
        if left <= 0:  # the closed loop's budget is spent: the sequence plays to its end, unobserved
            state.get_mutable_abstract_state(int(self._record)).set_value(replace(record, budget_spent=True))
            return
        t = float(context.get_time())
        rest = remainder(record.sequence, t - record.t0)
        if rest is None:
            return
        record = self._observe(context, record)
        if record.observed is None:  # never a good scene: nothing to plan on
            state.get_mutable_abstract_state(int(self._record)).set_value(record)
            return
        if self._on_track(record, t):  # the verified sequence goes on as verified
            state.get_mutable_abstract_state(int(self._record)).set_value(
                replace(record, on_track=record.on_track + 1)
            )
            return
        states = self._states(context)
        measured = all(o.name in states for o in record.observed.objects)
        scene = record.scene if measured and record.scene is not None else record.observed
        initial, alternatives, initialised = rest, None, False
        if self._initialiser is not None and self._moved_far(record, t):
            fresh = self._initialiser(record.observed, states[self._robot_name])
            if fresh is not None:
                initial, alternatives, initialised = fresh, (lambda: [rest]), True
        problem = ReplanProblem(
            scene,
            initial,
            start=RolloutStart(states),
            iterations=self._closed.iterations,
            rollouts=min(self._closed.rollouts, left),
            attempt=record.replans,
            alternatives=alternatives if initialised and left > 1 else None,
        )
        result = self._planner.replan(problem)
        prediction = None if result.outcome is None else result.outcome.prediction
        state.get_mutable_abstract_state(int(self._record)).set_value(
            replace(
                record,
                sequence=result.sequence,
                t0=t,
                prediction=prediction,
                replans=record.replans + 1,
                rollouts=record.rollouts + result.rollouts,
                initialised=record.initialised + int(initialised),
                changed=record.changed + int(result.sequence is not rest),
                reason=result.failure_reason,
                scene=scene,
                track=None,  # off track: re-optimised from here on
            )
        )

    @staticmethod
    def _off_by(prediction: Prediction | None, record: ControllerRecord, t: float) -> float | None:
        """How far the observed object that moved most is at ``t`` from where ``prediction`` (of
        the sequence commanded from ``record.t0``) had it, infinite if one appeared or went (the
        objects paired by position, ``largest_displacement``: a perceived scene's names follow the
        objects' order on the table, which a frame's noise may swap); None without a prediction."""
        expected = None if prediction is None else prediction.at(t - record.t0)
        if expected is None:
            return None
        observed = np.array([o.position for o in record.observed.objects])
        return largest_displacement(expected[0], observed)

    def _on_track(self, record: ControllerRecord, t: float) -> bool:
        """Whether every observed object is within ``closed_loop.track_distance`` of where the
        verified initial sequence's run on the execution model had it at ``t``."""
        distance = self._closed.track_distance
        off = self._off_by(record.track, record, t) if distance > 0 else None
        return off is not None and off <= distance

    def _moved_far(self, record: ControllerRecord, t: float) -> bool:
        """Whether an observed object is farther than ``closed_loop.replan_distance`` from where the
        commanded sequence's rollout put it at ``t``, or one appeared or went."""
        off = None if record.scene is None else self._off_by(record.prediction, record, t)
        return off is not None and off > self._closed.replan_distance

    def _calc_desired(self, context: Context, output) -> None:
        record: ControllerRecord = context.get_abstract_state(int(self._record)).get_value()
        if record.sequence is None:
            x = self._state.Eval(context)
            robot = self._instances[self._robot_name]
            q = self._plant.GetPositionsFromArray(robot, x[: self._plant.num_positions()])
            output.SetFromVector(np.concatenate([q, np.zeros_like(q)]))
            return
        trajectory = record.sequence.to_trajectory()
        s = float(context.get_time()) - record.t0
        if s >= record.sequence.duration:
            q = record.sequence.knots[-1]
            output.SetFromVector(np.concatenate([q, np.zeros_like(q)]))
            return
        s = max(s, 0.0)
        output.SetFromVector(
            np.concatenate([trajectory.value(s).ravel(), trajectory.EvalDerivative(s, 1).ravel()])
        )


__all__ = ["ControllerRecord", "Initialiser", "RecedingHorizonController", "remainder"]
