"""``RolloutWorld``: a world built once per scene, in which a control sequence is rolled out with contact.

The world is ``make_world_diagram`` at the rollout time step (``optimiser.rollout_time_step``) with a
C++ ``TrajectorySource`` driving the robot; the initial context is kept. A rollout swaps the source's
trajectory, resets the context and simulates, Python only reading the state (``Reading``) every
``optimiser.sample_period``. A reduced world has some objects welded (see ``scene_rollouts``).
"""

from __future__ import annotations

import copy
import time
from collections.abc import Iterable
from dataclasses import dataclass, replace
from functools import cached_property
from typing import TYPE_CHECKING, NamedTuple

import numpy as np
from pydrake.geometry import Role
from pydrake.multibody.tree import BodyIndex
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder

from hlp_drake.systems.control_sequence import ControlSequence
from hlp_drake.systems.robot import TCP_FRAME
from hlp_drake.systems.rollout_cost import RolloutOutcome, RolloutSamples, rollout_cost
from hlp_drake.systems.rollout_sampler import sample_rollout
from hlp_drake.systems.scene_models import TABLE_NAME, object_body, over_table_mask
from hlp_drake.systems.start_pose import tcp_keypoint_height
from hlp_drake.systems.weld_schedule import FixedWelds
from hlp_drake.systems.world import add_position_trajectory, make_world_diagram, world_plant

if TYPE_CHECKING:
    from hlp_drake.systems.scenario import Scenario

MOVED = 1.0e-3
"""A free object whose geometry has moved more than this from its start (m) is watched near welded ones."""


def simulation_failure(error: BaseException) -> str:
    """The first line of a Drake simulation failure: a ``RuntimeError``, or one of Drake's internal
    checks failing (pydrake raises those as ``SystemExit("Failure at ...")``, e.g. non-finite
    positions after a blow-up). Any other ``SystemExit`` is raised again."""
    if isinstance(error, SystemExit) and not str(error).startswith("Failure at"):
        raise error
    return str(error).splitlines()[0]


def rollout_scenario(scenario: Scenario) -> Scenario:
    """``scenario`` with the plant stepping at the optimiser's rollout time step."""
    plant = copy.copy(scenario.plant)
    plant.time_step = scenario.optimiser.rollout_time_step
    return replace(scenario, plant=plant)


def _rotation_angles(R_a: np.ndarray, R_b: np.ndarray) -> np.ndarray:
    """(n,) angles of the rotations taking each of the (n, 3, 3) ``R_a`` to ``R_b``."""
    cosine = (np.einsum("nij,nij->n", R_a, R_b) - 1.0) / 2.0
    return np.arccos(np.clip(cosine, -1.0, 1.0))


@dataclass(frozen=True)
class BodyPoses:
    """World poses of some bodies: (n, 3) origins and (n, 3, 3) rotations."""

    p: np.ndarray
    R: np.ndarray

    def motion(self, other: BodyPoses, radii: np.ndarray) -> np.ndarray:
        """(n,) bound on how far a point of each body's geometry is from where it was in ``other``
        (origin shift plus the turn times the geometry's radius about the origin)."""
        return np.linalg.norm(self.p - other.p, axis=1) + _rotation_angles(other.R, self.R) * radii


class Reading(NamedTuple):
    """The state of a rollout read at one sample."""

    positions: np.ndarray
    """(m, 3) object centres (the target first)."""
    tcp: np.ndarray
    """(3,) the tcp's position."""
    max_force: float
    """The largest contact force on an object, N."""
    table_contact: bool
    """Whether the robot touches the table."""
    problem: str | None
    """Why the simulation is not to be trusted (None if it is sane)."""


class RolloutWorld:
    """A pre-built world for rolling out control sequences on ``scenario``'s scene (one per worker process).

    With ``welded_objects`` it is a reduced world: those objects are welded at their scene poses, and
    ``near_welded`` tells which of them the robot or a moving object came near.
    """

    def __init__(self, scenario: Scenario, *, welded_objects: Iterable[str] = ()) -> None:
        scene = scenario.scene
        self.scene = scene
        self.scenario = scenario
        self.welded_objects = frozenset(welded_objects)
        builder = DiagramBuilder()
        world = builder.AddSystem(
            make_world_diagram(rollout_scenario(scenario), welded_objects=self.welded_objects, cameras=False)
        )
        plant, robot = world_plant(world)
        start = plant.GetPositions(plant.CreateDefaultContext(), robot)
        hold = ControlSequence(np.array([0.0, 1.0]), np.vstack([start, start])).to_trajectory()
        self._source = add_position_trajectory(builder, world, hold)
        self.diagram = builder.Build()
        self.plant, self.robot = plant, robot
        self.start_positions = start
        self.world = world
        self._simulator = Simulator(self.diagram)
        self._context = self._simulator.get_mutable_context()
        self._plant_context = plant.GetMyMutableContextFromRoot(self._context)
        self._world_context = world.GetMyContextFromRoot(self._context)
        self._query = world.GetOutputPort("query_object")
        self._initial = self._context.Clone()
        self.objects = [object_body(plant, obj.name) for obj in scene.objects]
        self.object_bodies = {int(body.index()) for body in self.objects}
        self._table_bodies = {int(i) for i in plant.GetBodyIndices(plant.GetModelInstanceByName(TABLE_NAME))}
        self.robot_bodies = {int(i) for i in plant.GetBodyIndices(robot)}
        self._tcp = plant.GetFrameByName(TCP_FRAME, robot)
        self._tcp_height = tcp_keypoint_height(scene, scenario.ik)
        inspector = world.GetSubsystemByName("scene_graph").model_inspector()
        self.geometry_body = {
            g: int(plant.GetBodyFromFrameId(inspector.GetFrameId(g)).index())
            for g in inspector.GetAllGeometryIds(Role.kProximity)
        }
        self._welded_bodies = {
            int(b.index()): b.name() for b in self.objects if b.name() in self.welded_objects
        }
        self._moving = [robot] + [
            b.model_instance() for b in self.objects if b.name() not in self.welded_objects
        ]
        robot_bodies = [plant.get_body(i) for i in plant.GetBodyIndices(robot)]
        self._num_robot_watched = len(robot_bodies)
        self._watched = robot_bodies + self.objects
        self._watched_radii = np.array([self._body_radius(inspector, b) for b in self._watched])

    def _body_radius(self, inspector, body) -> float:
        """Radius about the body's origin of a sphere holding its collision geometry, m."""
        radius = 0.0
        for g in self.plant.GetCollisionGeometriesForBody(body):
            box = inspector.GetObbInGeometryFrame(g)
            centre = inspector.GetPoseInFrame(g) @ box.center()
            radius = max(radius, float(np.linalg.norm(centre) + np.linalg.norm(box.half_width())))
        return radius

    @cached_property
    def start_collisions(self) -> tuple[str, ...]:
        """Names of the bodies the robot penetrates in the initial state (computed on first use: of
        a scene's worlds only the full one is asked)."""
        query = self.world.GetOutputPort("query_object").Eval(self.world.GetMyContextFromRoot(self._initial))
        hits = set()
        for pair in query.ComputePointPairPenetration():
            a, b = (self.plant.get_body(BodyIndex(self.geometry_body[g])) for g in (pair.id_A, pair.id_B))
            a_robot, b_robot = int(a.index()) in self.robot_bodies, int(b.index()) in self.robot_bodies
            if a_robot != b_robot:
                hits.add((b if a_robot else a).name())
        return tuple(sorted(hits))

    def begin(
        self, sequence: ControlSequence, *, time: float = 0.0, states: dict[str, np.ndarray] | None = None
    ) -> None:
        """Load ``sequence`` and reset to the initial state, or to time ``time`` with the given model
        instances' states (``states()`` of another world of this scene; the rest start at rest)."""
        self._source.UpdateTrajectory(sequence.to_trajectory())
        self._context.SetTimeStateAndParametersFrom(self._initial)
        if states is not None:
            self._context.SetTime(time)
            for name, x in states.items():
                instance = self.plant.GetModelInstanceByName(name)
                self.plant.SetPositionsAndVelocities(self._plant_context, instance, x)
        self._simulator.Initialize()

    def states(self) -> dict[str, np.ndarray]:
        """Positions and velocities of the robot and of every free object, by model instance name."""
        plant = self.plant
        return {
            plant.GetModelInstanceName(i): plant.GetPositionsAndVelocities(self._plant_context, i)
            for i in self._moving
        }

    def advance_to(self, t: float) -> str | None:
        """Simulate up to time ``t``; why the solver failed (None if it did not)."""
        try:
            self._simulator.AdvanceTo(float(t))
        except (RuntimeError, SystemExit) as error:
            return f"the solver failed at t = {self._context.get_time():.2f} s: {simulation_failure(error)}"
        return None

    def time(self) -> float:
        return self._context.get_time()

    def watched_poses(self) -> BodyPoses:
        """Poses of the robot's bodies and of every object (for ``near_welded``)."""
        X = np.array([body.EvalPoseInWorld(self._plant_context).GetAsMatrix34() for body in self._watched])
        return BodyPoses(X[:, :, 3], X[:, :, :3])

    def near_welded(self, poses: BodyPoses, previous: BodyPoses, start: BodyPoses) -> tuple[str, ...]:
        """The welded objects within ``sto.weld_margin`` plus the largest motion of a watched body since
        ``previous`` of the robot or of an object that has moved since ``start`` (the poses now)."""
        if not self._welded_bodies:
            return ()
        radii = self._watched_radii
        moved = poses.motion(start, radii) > MOVED
        moved[: self._num_robot_watched] = True  # the robot always counts
        step = float(np.max(poses.motion(previous, radii)[moved], initial=0.0))
        margin = self.scenario.optimiser.weld_margin + step
        watched = {int(b.index()) for b, m in zip(self._watched, moved) if m}
        near = set()
        for pair in self._query.Eval(self._world_context).ComputeSignedDistancePairwiseClosestPoints(margin):
            a, b = self.geometry_body[pair.id_A], self.geometry_body[pair.id_B]
            for welded, other in ((a, b), (b, a)):
                if welded in self._welded_bodies and other in watched:
                    near.add(self._welded_bodies[welded])
        return tuple(obj.name for obj in self.scene.objects if obj.name in near)

    def read(self) -> Reading:
        """The rollout's state now."""
        plant, context = self.plant, self._plant_context
        positions = np.array([body.EvalPoseInWorld(context).translation() for body in self.objects])
        speeds = [
            np.linalg.norm(body.EvalSpatialVelocityInWorld(context).translational()) for body in self.objects
        ]
        tcp = self._tcp.CalcPoseInWorld(context).translation()
        results = plant.get_contact_results_output_port().Eval(context)
        max_force, table_contact = 0.0, False
        for i in range(results.num_point_pair_contacts()):
            info = results.point_pair_contact_info(i)
            a, b = int(info.bodyA_index()), int(info.bodyB_index())
            if a in self.object_bodies or b in self.object_bodies:
                max_force = max(max_force, float(np.linalg.norm(info.contact_force())))
            if (a in self.robot_bodies and b in self._table_bodies) or (
                b in self.robot_bodies and a in self._table_bodies
            ):
                table_contact = True
        problem = None
        sto = self.scenario.optimiser
        table = self.scene.table
        if not (np.all(np.isfinite(positions)) and np.all(np.isfinite(tcp))):
            return Reading(positions, tcp, max_force, table_contact, "a position is not finite")
        # Objects pushed off the edge fall freely (a legitimate outcome); only objects over the table
        # are checked for impossible speeds and for sinking into it.
        over = over_table_mask(positions, table)
        speeds = np.where(over, speeds, 0.0)
        sunk = over & (positions[:, 2] < table.height - sto.max_sink)  # a centre inside the table top
        if np.max(speeds) > sto.max_object_speed:
            name = self.scene.objects[int(np.argmax(speeds))].name
            problem = (
                f"{name} moves at {np.max(speeds):.1f} m/s over the table (limit {sto.max_object_speed} m/s)"
            )
        elif np.any(sunk):
            problem = f"{self.scene.objects[int(np.argmax(sunk))].name} sank into the table"
        return Reading(positions, tcp, max_force, table_contact, problem)

    def world_with(self, welded: frozenset[str]) -> RolloutWorld | None:
        """This world if ``welded`` are its welded objects, else None (a ``WorldSet`` of one world)."""
        return self if welded == self.welded_objects else None

    def simulate(self, sequence: ControlSequence) -> RolloutSamples:
        """Roll ``sequence`` out from the initial state and read the state every sample period (on a
        reduced world, up to the first sample at which something came near a welded object)."""
        return sample_rollout(sequence, self.scenario.optimiser, self, FixedWelds(self.welded_objects))

    def cost(self, samples: RolloutSamples, sequence: ControlSequence) -> RolloutOutcome:
        """The cost of ``sequence``'s rollout from its ``samples``.

        Raises:
            ValueError: the samples stopped because something came near a welded object.
        """
        if samples.touched:
            raise ValueError(f"the rollout came near the welded {', '.join(samples.touched)}")
        return rollout_cost(
            samples,
            self.scene,
            self.scenario.optimiser,
            tcp_height=self._tcp_height,
            effort=sequence.effort(),
            step_duration=float(np.mean(sequence.steps)),
        )

    def rollout(self, sequence: ControlSequence) -> RolloutOutcome:
        """Simulate ``sequence`` and cost it (see ``cost``)."""
        return timed_rollout(sequence, self.simulate, self)


def timed_rollout(sequence: ControlSequence, simulate, costing: RolloutWorld) -> RolloutOutcome:
    """``simulate(sequence)`` costed by ``costing``, with the welding record and the wall time."""
    started = time.perf_counter()
    samples = simulate(sequence)
    outcome = replace(costing.cost(samples, sequence), welded=samples.welded, switches=samples.switches)
    return replace(outcome, wall_s=time.perf_counter() - started)
