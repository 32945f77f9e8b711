"""``RolloutWorld``: a world built once per scene, in which a control sequence is rolled out with contact.

The world is ``world_diagram`` of the spec's scene and world model: the execution model itself (its plant, contact
geometry and settling), with a C++ ``TrajectorySource`` driving the robot; the initial context is
kept. A rollout swaps the source's trajectory, resets the context (or sets a given start state) and
simulates, Python only reading the state (``Reading``) every ``planner.low_level.sample_period``. Objects
may be put to sleep (their floating joints locked in the context: they neither move nor cost the
contact solver a degree of freedom) and woken again, at any pose (the reduced model,
``rollout_sampler``). A rollout from the scene's start with every object awake keeps its end state
(``RolloutOutcome.final``): the execution of that sequence starts from there rather than simulating
the reach again.
"""

from __future__ import annotations

import time
from collections.abc import Iterable
from dataclasses import replace
from functools import cached_property
from typing import TYPE_CHECKING

import numpy as np
from pydrake.geometry import CollisionFilterDeclaration, GeometrySet, Role
from pydrake.multibody.tree import BodyIndex
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder

from hlp_drake.systems.low_level.control_sequence import ControlSequence
from hlp_drake.systems.low_level.outcome import FinalState, Prediction, RolloutOutcome, RolloutStart
from hlp_drake.systems.low_level.sto.cost import RolloutSamples, rollout_cost
from hlp_drake.systems.low_level.sto.sampler import (
    OBJECT,
    OTHER,
    ROBOT,
    TABLE,
    BodyPoses,
    Reading,
    contact_summary,
    sample_rollout,
)
from hlp_drake.systems.low_level.sto.sleep import AWAKE, ProximityContext
from hlp_drake.systems.world.scene_models import TABLE_NAME, object_body, over_table_mask
from hlp_drake.systems.world.simulation import simulation_failure
from hlp_drake.systems.world.start_pose import tcp_keypoint_height
from hlp_drake.systems.world.world import add_position_trajectory, world_diagram, world_plant

if TYPE_CHECKING:
    from hlp_drake.systems.low_level.sto.spec import RolloutSpec


class RolloutWorld:
    """A pre-built world for rolling out control sequences on ``spec``'s scene, in its world model
    (one per worker process).

    Every object is a free body; ``begin(..., asleep=...)`` and ``set_asleep`` lock and unlock their
    joints (``rollout_sampler``).
    """

    def __init__(self, spec: RolloutSpec) -> None:
        self.key = spec.key
        scene = spec.scene
        self.scene = scene
        self.spec = spec
        builder = DiagramBuilder()
        world = builder.AddSystem(world_diagram(scene, spec.model))
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
        self._initial = self._context.Clone()
        self.objects = [object_body(plant, obj.name) for obj in scene.objects]
        self.object_bodies = {int(body.index()) for body in self.objects}
        self._object_names = {int(body.index()): body.name() for body in self.objects}
        self.object_names = [body.name() for body in self.objects]
        """The objects' names, in scene order."""
        self._joints = {
            b.name(): [plant.get_joint(j) for j in plant.GetJointIndices(b.model_instance())]
            for b in self.objects
        }
        self._table_bodies = {int(i) for i in plant.GetBodyIndices(plant.GetModelInstanceByName(TABLE_NAME))}
        self.robot_bodies = {int(i) for i in plant.GetBodyIndices(robot)}
        self._tcp = plant.GetFrameByName(spec.model.robot.tcp_frame, robot)
        self._tcp_height = tcp_keypoint_height(scene, spec.model.ik)
        inspector = world.GetSubsystemByName("scene_graph").model_inspector()
        self.geometry_body = {
            g: int(plant.GetBodyFromFrameId(inspector.GetFrameId(g)).index())
            for g in inspector.GetAllGeometryIds(Role.kProximity)
        }
        self._instances = [robot] + [b.model_instance() for b in self.objects]
        self._scene_graph = world.GetSubsystemByName("scene_graph")
        self._scene_graph_context = self._scene_graph.GetMyMutableContextFromRoot(self._context)
        self._geometries = {b.name(): plant.GetCollisionGeometriesForBody(b) for b in self.objects}
        self._table_geometry = GeometrySet(
            [g for g, body in self.geometry_body.items() if body in self._table_bodies]
        )
        self._filter = None
        robot_bodies = [plant.get_body(i) for i in plant.GetBodyIndices(robot)]
        self._num_robot_watched = len(robot_bodies)
        self._watched = robot_bodies + self.objects
        self._watched_radii = np.array([self._body_radius(inspector, b) for b in self._watched])
        # each object's quaternion floating joint: positions (qw, qx, qy, qz, x, y, z), velocities (w, v)
        self._object_q = np.array([b.floating_positions_start() + np.arange(4, 7) for b in self.objects])
        self._object_v = np.array([b.floating_velocities_start_in_v() + np.arange(6) for b in self.objects])
        self._proximity = ProximityContext(self)
        self._body_kind = np.full(plant.num_bodies(), OTHER)
        for kind, bodies in (
            (ROBOT, self.robot_bodies),
            (OBJECT, self.object_bodies),
            (TABLE, self._table_bodies),
        ):
            self._body_kind[sorted(bodies)] = kind

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
        self,
        sequence: ControlSequence,
        *,
        time: float = 0.0,
        states: dict[str, np.ndarray] | None = None,
        asleep: Iterable[str] = (),
    ) -> None:
        """Load ``sequence`` and reset to the initial state, or to time ``time`` with the given model
        instances' states (``states()``'s or a ``RolloutStart``'s form; the rest start as in the
        scene), with the objects ``asleep`` asleep."""
        self._source.UpdateTrajectory(sequence.to_trajectory())
        self._context.SetTimeStateAndParametersFrom(self._initial)
        if states is not None:
            self._context.SetTime(time)
            for name, x in states.items():
                instance = self.plant.GetModelInstanceByName(name)
                self.plant.SetPositionsAndVelocities(self._plant_context, instance, x)
        self._filter = None  # the reset dropped the sleeping objects' collision filter
        self.set_asleep(frozenset(), frozenset(asleep))
        self._simulator.Initialize()

    def set_asleep(self, before: frozenset[str], after: frozenset[str]) -> None:
        """Put the objects of ``after`` but not ``before`` to sleep (their joints locked, velocities
        zeroed) and wake those of ``before`` but not ``after``. Sleeping objects' contacts with the
        table and with each other are filtered out (neither moves)."""
        for name in after - before:
            for joint in self._joints[name]:
                joint.Lock(self._plant_context)
        for name in before - after:
            for joint in self._joints[name]:
                joint.Unlock(self._plant_context)
        if after == before and self._filter is not None:
            return
        manager = self._scene_graph.collision_filter_manager(self._scene_graph_context)
        if self._filter is not None:
            manager.RemoveDeclaration(self._filter)
            self._filter = None
        if after:
            sleeping = GeometrySet([g for name in after for g in self._geometries[name]])
            self._filter = manager.ApplyTransient(
                CollisionFilterDeclaration()
                .ExcludeWithin(sleeping)
                .ExcludeBetween(sleeping, self._table_geometry)
            )

    def states(self) -> dict[str, np.ndarray]:
        """Positions and velocities of the robot and of every object, by model instance name."""
        plant = self.plant
        return {
            plant.GetModelInstanceName(i): plant.GetPositionsAndVelocities(self._plant_context, i)
            for i in self._instances
        }

    def advance_to(self, t: float) -> str | None:
        """Simulate up to time ``t``; why the solver failed (None if it did not), a state that is not
        finite at the end counting as a failure (every later query of it would fail in Drake)."""
        try:
            self._simulator.AdvanceTo(float(t))
        except (RuntimeError, SystemExit) as error:
            return f"the solver failed at t = {self._context.get_time():.2f} s: {simulation_failure(error)}"
        if not np.all(np.isfinite(self.plant.GetPositionsAndVelocities(self._plant_context))):
            return f"the solver diverged: the state is not finite at t = {self._context.get_time():.2f} s"
        return None

    def time(self) -> float:
        return self._context.get_time()

    def watched_poses(self) -> BodyPoses:
        """Poses of the robot's bodies and of every object (for ``rollout_sampler``'s checks)."""
        X = np.array([body.EvalPoseInWorld(self._plant_context).GetAsMatrix34() for body in self._watched])
        return BodyPoses(X[:, :, 3], X[:, :, :3])

    def motion_bounds(self, poses: BodyPoses, other: BodyPoses) -> np.ndarray:
        """(robot bodies + objects,) how far a point of each watched body moved from ``other`` to ``poses``."""
        return poses.motion(other, self._watched_radii)

    @property
    def num_robot_bodies(self) -> int:
        """The watched bodies are the robot's (this many, first) and then the objects (in scene order)."""
        return self._num_robot_watched

    def close_pairs(self, threshold: float) -> list[tuple[int, int, float]]:
        """(body, body, distance) of the robot-object and object-object pairs within ``threshold`` of
        each other now (m; ``ProximityContext``: the objects' shapes, not their support spheres)."""
        self._proximity.set_positions(self.plant.GetPositions(self._plant_context))
        return self._proximity.close_pairs(threshold)

    def object_name(self, body: int) -> str | None:
        """The scene object of body index ``body`` (None: the robot or the table)."""
        return self._object_names.get(body)

    def object_speeds(self) -> tuple[np.ndarray, np.ndarray]:
        """Per object (scene order), its translational (m/s) and angular (rad/s) speed."""
        v = self.plant.GetVelocities(self._plant_context)[self._object_v]  # (m, 6): w then v, in world
        return np.linalg.norm(v[:, 3:], axis=1), np.linalg.norm(v[:, :3], axis=1)

    def object_positions(self) -> np.ndarray:
        """(m, 3) object centres (scene order): their floating joints' translations."""
        return self.plant.GetPositions(self._plant_context)[self._object_q]

    def read(self) -> Reading:
        """The rollout's state now."""
        plant, context = self.plant, self._plant_context
        positions = self.object_positions()
        speeds = self.object_speeds()[0]
        tcp = self._tcp.CalcPoseInWorld(context).translation()
        max_force, table_contact = contact_summary(
            plant.get_contact_results_output_port().Eval(context), self._body_kind
        )
        problem = None
        sto = self.spec.sto
        table = self.scene.table
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

    def simulate(self, sequence: ControlSequence, start: RolloutStart | None = None) -> RolloutSamples:
        """Roll ``sequence`` out from the initial state (or ``start``) with every object awake,
        reading the state every sample period (the full model)."""
        return sample_rollout(
            sequence, self.spec.sto, self, AWAKE, settle_s=self.spec.success.settle_s, start=start
        )

    def cost(self, samples: RolloutSamples, sequence: ControlSequence) -> RolloutOutcome:
        """The cost of ``sequence``'s rollout from its ``samples``."""
        return rollout_cost(
            samples,
            self.scene,
            self.spec.sto,
            success=self.spec.success,
            tcp_height=self._tcp_height,
            effort=sequence.effort(),
            step_duration=float(np.mean(sequence.steps)),
        )

    def rollout(self, sequence: ControlSequence, start: RolloutStart | None = None) -> RolloutOutcome:
        """Simulate ``sequence`` (from ``start``) and cost it (see ``cost``)."""
        return timed_rollout(sequence, self.simulate, self, start)


def timed_rollout(
    sequence: ControlSequence, simulate, costing: RolloutWorld, start: RolloutStart | None = None
) -> RolloutOutcome:
    """``simulate(sequence, start)`` costed by ``costing``, with the sleeping record and the wall time
    (and, from the scene's start with every object awake at the end, the end state)."""
    started = time.perf_counter()
    samples = simulate(sequence, start)
    prediction = Prediction(samples.times, samples.positions, samples.tcp)
    final = None
    if start is None and not samples.asleep and samples.switches == 0:
        final = FinalState(costing.spec.world_key, costing.time(), costing.states())
    outcome = replace(
        costing.cost(samples, sequence),
        asleep=samples.asleep,
        switches=samples.switches,
        prediction=prediction,
        final=final,
    )
    return replace(outcome, wall_s=time.perf_counter() - started)
