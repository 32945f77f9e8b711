"""One STO rollout: a control sequence simulated with contact in the world, and its cost.

``RolloutWorld(scene, config)`` builds the world diagram once (``make_world_diagram`` at the rollout
time step ``config.sto.rollout_time_step``) with a C++ ``TrajectorySource`` driving the robot, and
keeps the initial context. ``rollout(sequence)`` swaps the source's trajectory, resets the context and
simulates; Python only reads the state every ``config.sto.sample_period`` seconds for the cost.

The reduced model (``config.sto.reduced_model``, ``SceneRollouts``): most of a rollout's time goes
to the contact problem, which every resting object joins with its contact points on the table. An
object nothing has come near stays at rest, so until then it can as well be welded. A reduced
rollout starts with the objects welded that the robot's collision geometry, following the commanded
motion (``RolloutWorld.approach_times``), does not come within ``sto.weld_clearance`` of in the next
``sto.weld_lookahead`` seconds, and frees them as that changes. At every sample it also checks that
neither the robot nor an object that has moved came within ``sto.weld_margin`` (plus the largest
motion of a body since the previous sample) of a welded object; if one did, the rollout goes back
to the previous sample and on with it freed (``sample_rollout``). Each welded set is a world of its
own (``RolloutWorld(..., welded_objects=...)``), built once; moving on carries the robot's and the
free objects' states over. Every cost term still covers every object: a welded one stays put.

The cost (``StoCost``) is computed by ``rollout_cost`` from the sampled states (``RolloutSamples``),
a pure function: goal distance at the end, objects off the table, robot-table contact, high contact
forces on objects, disturbance of the obstacles and of the target, ending next to an obstacle, and
the control effort.
"""

from __future__ import annotations

import copy
import math
import time
from collections import OrderedDict
from collections.abc import Iterable
from dataclasses import dataclass, replace
from functools import cached_property

import numpy as np
from pydrake.geometry import CollisionFilterDeclaration, GeometrySet, Role
from pydrake.multibody.tree import BodyIndex
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder

from hlp_drake.scene.model import Scene
from hlp_drake.systems.control_sequence import ControlSequence
from hlp_drake.systems.robot import TCP_FRAME
from hlp_drake.systems.scene_models import TABLE_NAME, object_body, off_table_mask, over_table_mask
from hlp_drake.systems.sto_config import StoConfig
from hlp_drake.systems.world import (
    add_position_trajectory,
    make_world_diagram,
    tcp_keypoint_height,
    world_plant,
)
from hlp_drake.systems.world_config import WorldConfig

BLOWN_UP_COST = 1.0e9
"""Cost of a rollout whose simulation failed or blew up (ranked below every sane one)."""
MOVED = 1.0e-3
"""A free object whose geometry has moved more than this from its start (m) is watched near welded ones."""


@dataclass(frozen=True)
class RolloutSamples:
    """A rollout's state read every sample period (T samples, m objects; object 0 is the target).

    Attributes:
        times: (T,) sample times, s.
        positions: (T, m, 3) object centres.
        tcp: (T, 3) tcp positions.
        max_force: (T,) largest contact force magnitude on any object, N.
        table_contact: (T,) whether the robot touched the table.
        blew_up: why the simulation is not to be trusted (None if it is sane).
        touched: welded objects something came near where no world with them freed was at hand (the
            samples stop there; see ``sample_rollout``).
        welded: the objects that stayed welded throughout (reduced worlds only).
        switches: how often the rollout moved on to a world with fewer objects welded.
    """

    times: np.ndarray
    positions: np.ndarray
    tcp: np.ndarray
    max_force: np.ndarray
    table_contact: np.ndarray
    blew_up: str | None = None
    touched: tuple[str, ...] = ()
    welded: tuple[str, ...] = ()
    switches: int = 0


@dataclass(frozen=True)
class RolloutOutcome:
    """A rollout's cost and final state.

    Attributes:
        cost: total cost (``BLOWN_UP_COST`` if the simulation blew up).
        terms: the cost's terms by name.
        success: the paper's test at the end: target inside the pre-grasp region, nothing fell, sane.
        failure_reason: why not, one line (None on success).
        target_distance: final horizontal tcp-to-target distance, m.
        fallen: names of the objects off the table at the end.
        simulated_s, wall_s: simulated and wall-clock time of the rollout.
        welded: the objects that stayed welded throughout (empty: the full model).
        switches: how often the rollout moved on to a world with fewer objects welded.
    """

    cost: float
    terms: dict[str, float]
    success: bool
    failure_reason: str | None
    target_distance: float
    fallen: tuple[str, ...] = ()
    simulated_s: float = 0.0
    wall_s: float = 0.0
    welded: tuple[str, ...] = ()
    switches: int = 0


def _half_extent(size: tuple[float, float, float]) -> float:
    return 0.5 * max(size[0], size[1])


def pregrasp_check(tcp: np.ndarray, target_position: np.ndarray, scene: Scene, *, tcp_height: float,
                   margin: float) -> tuple[bool, float]:
    """Whether the target (centre at ``target_position``) is inside the gripper's pre-grasp region at
    tcp position ``tcp``: horizontally within the target's radius + ``margin``, and the tcp within
    ``margin`` of the grasp height. Also returns the horizontal distance."""
    distance = float(np.hypot(*(np.asarray(tcp)[:2] - np.asarray(target_position)[:2])))
    inside = distance <= _half_extent(scene.target.size) + margin and abs(tcp[2] - tcp_height) <= margin
    return inside, distance


def simulation_failure(error: BaseException) -> str:
    """The first line of a Drake simulation failure: a ``RuntimeError``, or one of Drake's internal
    checks failing (pydrake raises those as ``SystemExit("Failure at ...")``, e.g. non-finite
    positions after a blow-up). Any other ``SystemExit`` is raised again."""
    if isinstance(error, SystemExit) and not str(error).startswith("Failure at"):
        raise error
    return str(error).splitlines()[0]


def reach_problem(fallen, inside: bool, distance: float) -> str | None:
    """Why a reach failed the success test (None if it passed)."""
    if fallen:
        return f"objects fell off the table: {', '.join(fallen)}"
    if not inside:
        return f"the target is not in the gripper's pre-grasp region (tcp {distance:.3f} m away)"
    return None


def rollout_cost(samples: RolloutSamples, scene: Scene, sto: StoConfig, *, tcp_height: float,
                 effort: float, step_duration: float) -> RolloutOutcome:
    """The cost of a rollout from its samples (see ``StoCost`` for the terms)."""
    weights = sto.cost
    names = [obj.name for obj in scene.objects]
    simulated = float(samples.times[-1]) if len(samples.times) else 0.0
    if samples.blew_up is not None:
        return RolloutOutcome(BLOWN_UP_COST, {"blew_up": BLOWN_UP_COST}, False,
                              f"the simulation blew up: {samples.blew_up}", math.inf, simulated_s=simulated)
    positions, tcp = samples.positions, samples.tcp
    per_step = (samples.times[1] - samples.times[0]) / step_duration if len(samples.times) > 1 else 1.0
    off = np.array([off_table_mask(p, scene.table) for p in positions])  # (T, m)
    final = positions[-1]
    start = positions[0]
    inside, distance = pregrasp_check(tcp[-1], final[0], scene, tcp_height=tcp_height,
                                      margin=weights.pregrasp_margin)
    moved = np.sum((final[:, :2] - start[:, :2]) ** 2, axis=1)
    near = [
        name for name, obj, p, gone in zip(names[1:], scene.obstacles, final[1:], off[-1, 1:])
        if not gone and np.hypot(*(tcp[-1, :2] - p[:2])) <= _half_extent(obj.size) + weights.near_distance
    ]
    excess = np.clip(samples.max_force - weights.force_limit, 0.0, None)
    terms = {
        "goal": distance if inside else weights.goal_weight * distance,
        "off_table": weights.off_table * float(np.sum(off)) * per_step,
        "table_contact": weights.table_contact * float(np.sum(samples.table_contact)) * per_step,
        "force": weights.force_weight * float(np.sum(excess)) * per_step,
        "disturbance": weights.disturbance_weight * float(np.sum(moved[1:])),
        "target_disturbance": weights.target_disturbance_weight * float(moved[0]),
        "near_obstacle": weights.near_obstacle * len(near),
        "effort": weights.effort_weight * effort,
    }
    fallen = tuple(name for name, f in zip(names, off[-1]) if f)
    reason = reach_problem(fallen, inside, distance)
    return RolloutOutcome(float(sum(terms.values())), terms, reason is None, reason, distance, fallen, simulated)


def rollout_world_config(config: WorldConfig) -> WorldConfig:
    """``config`` with the plant stepping at the rollout time step and no MeshCat."""
    rollout = copy.deepcopy(config)
    rollout.plant.time_step = config.sto.rollout_time_step
    rollout.meshcat = False
    return rollout


def _rotation_angles(R_a: np.ndarray, R_b: np.ndarray) -> np.ndarray:
    """(n,) angles of the rotations taking each of the (n, 3, 3) ``R_a`` to ``R_b``."""
    cosine = (np.einsum("nij,nij->n", R_a, R_b) - 1.0) / 2.0
    return np.arccos(np.clip(cosine, -1.0, 1.0))


@dataclass(frozen=True)
class _BodyPoses:
    """World poses of some bodies: (n, 3) origins and (n, 3, 3) rotations."""

    p: np.ndarray
    R: np.ndarray

    def motion(self, other: _BodyPoses, radii: np.ndarray) -> np.ndarray:
        """(n,) bound on how far a point of each body's geometry is from where it was in ``other``
        (origin shift plus the turn times the geometry's radius about the origin)."""
        return np.linalg.norm(self.p - other.p, axis=1) + _rotation_angles(other.R, self.R) * radii


class RolloutWorld:
    """A pre-built world for rolling out control sequences on one scene (one per worker process).

    With ``welded_objects`` it is a reduced world: those objects are welded at their scene poses, and
    ``near_welded`` tells which of them the robot or a moving object came near.
    """

    def __init__(self, scene: Scene, config: WorldConfig | None = None, *,
                 welded_objects: Iterable[str] = ()) -> None:
        config = WorldConfig() if config is None else config
        self.scene = scene
        self.config = config
        self.welded_objects = frozenset(welded_objects)
        builder = DiagramBuilder()
        world = builder.AddSystem(make_world_diagram(scene, rollout_world_config(config),
                                                     welded_objects=self.welded_objects))
        plant, robot = world_plant(world)
        start = plant.GetPositions(plant.CreateDefaultContext(), robot)
        hold = ControlSequence(np.array([0.0, 1.0]), np.vstack([start, start])).to_trajectory()
        self._source = add_position_trajectory(builder, world, hold)
        self.diagram = builder.Build()
        self.plant, self.robot = plant, robot
        self.start_positions = start
        self._world = world
        self._simulator = Simulator(self.diagram)
        self._context = self._simulator.get_mutable_context()
        self._plant_context = plant.GetMyMutableContextFromRoot(self._context)
        self._world_context = world.GetMyContextFromRoot(self._context)
        self._query = world.GetOutputPort("query_object")
        self._initial = self._context.Clone()
        self._objects = [object_body(plant, obj.name) for obj in scene.objects]
        self._object_bodies = {int(body.index()) for body in self._objects}
        self._table_bodies = {int(i) for i in plant.GetBodyIndices(plant.GetModelInstanceByName(TABLE_NAME))}
        self._robot_bodies = {int(i) for i in plant.GetBodyIndices(robot)}
        self._tcp = plant.GetFrameByName(TCP_FRAME, robot)
        self._tcp_height = tcp_keypoint_height(scene, config)
        inspector = world.GetSubsystemByName("scene_graph").model_inspector()
        self._geometry_body = {
            g: int(plant.GetBodyFromFrameId(inspector.GetFrameId(g)).index())
            for g in inspector.GetAllGeometryIds(Role.kProximity)
        }
        self._welded_bodies = {int(b.index()): b.name() for b in self._objects if b.name() in self.welded_objects}
        self._moving = [robot] + [b.model_instance() for b in self._objects if b.name() not in self.welded_objects]
        robot_bodies = [plant.get_body(i) for i in plant.GetBodyIndices(robot)]
        self._num_robot_watched = len(robot_bodies)
        self._watched = robot_bodies + self._objects
        self._watched_radii = np.array([self._body_radius(inspector, b) for b in self._watched])
        self._sweep_context = None

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
        query = self._world.GetOutputPort("query_object").Eval(self._world.GetMyContextFromRoot(self._initial))
        hits = set()
        for pair in query.ComputePointPairPenetration():
            a, b = (self.plant.get_body(BodyIndex(self._geometry_body[g])) for g in (pair.id_A, pair.id_B))
            a_robot, b_robot = int(a.index()) in self._robot_bodies, int(b.index()) in self._robot_bodies
            if a_robot != b_robot:
                hits.add((b if a_robot else a).name())
        return tuple(sorted(hits))

    def _make_sweep_context(self):
        """A context of its own in which SceneGraph only checks robot-object pairs (for ``approach_times``)."""
        context = self.diagram.CreateDefaultContext()
        scene_graph = self._world.GetSubsystemByName("scene_graph")
        geometries = {"robot": [], "objects": [], "table": []}
        for g, body in self._geometry_body.items():
            kind = "robot" if body in self._robot_bodies else "objects" if body in self._object_bodies else "table"
            geometries[kind].append(g)
        robot, objects, table = (GeometrySet(geometries[k]) for k in ("robot", "objects", "table"))
        scene_graph.collision_filter_manager(scene_graph.GetMyMutableContextFromRoot(context)).Apply(
            CollisionFilterDeclaration().ExcludeWithin(robot).ExcludeWithin(objects)
            .ExcludeBetween(robot, table).ExcludeBetween(objects, table))
        return context

    def approach_times(self, sequence: ControlSequence, clearance: float) -> dict[str, float]:
        """Per object, the first time the robot's collision geometry comes within ``clearance`` of it
        when following ``sequence``'s commanded motion exactly, the objects at their scene poses
        (checked every sample period and at every knot; inf if never)."""
        if self._sweep_context is None:
            self._sweep_context = self._make_sweep_context()
        context = self._sweep_context
        plant_context = self.plant.GetMyMutableContextFromRoot(context)
        world_context = self._world.GetMyContextFromRoot(context)
        trajectory = sequence.to_trajectory()
        names = {int(b.index()): b.name() for b in self._objects}
        first = {obj.name: math.inf for obj in self.scene.objects}
        times = np.union1d(sequence.times, np.arange(0.0, sequence.duration, self.config.sto.sample_period))
        for t in times:
            self.plant.SetPositions(plant_context, self.robot, trajectory.value(t).ravel())
            for pair in self._query.Eval(world_context).ComputeSignedDistancePairwiseClosestPoints(clearance):
                for g in (pair.id_A, pair.id_B):
                    name = names.get(self._geometry_body[g])
                    if name is not None and first[name] == math.inf:
                        first[name] = float(t)
        return first

    def begin(self, sequence: ControlSequence, *, time: float = 0.0,
              states: dict[str, np.ndarray] | None = None) -> None:
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
        return {plant.GetModelInstanceName(i): plant.GetPositionsAndVelocities(self._plant_context, i)
                for i in self._moving}

    def advance_to(self, t: float) -> str | None:
        """Simulate up to time ``t``; why the solver failed (None if it did not)."""
        try:
            self._simulator.AdvanceTo(float(t))
        except (RuntimeError, SystemExit) as error:
            return f"the solver failed at t = {self._context.get_time():.2f} s: {simulation_failure(error)}"
        return None

    def time(self) -> float:
        return self._context.get_time()

    def watched_poses(self) -> _BodyPoses:
        """Poses of the robot's bodies and of every object (for ``near_welded``)."""
        X = np.array([body.EvalPoseInWorld(self._plant_context).GetAsMatrix34() for body in self._watched])
        return _BodyPoses(X[:, :, 3], X[:, :, :3])

    def near_welded(self, poses: _BodyPoses, previous: _BodyPoses, start: _BodyPoses) -> tuple[str, ...]:
        """The welded objects within ``sto.weld_margin`` plus the largest motion of a watched body since
        ``previous`` of the robot or of an object that has moved since ``start`` (the poses now)."""
        if not self._welded_bodies:
            return ()
        radii = self._watched_radii
        moved = poses.motion(start, radii) > MOVED
        moved[: self._num_robot_watched] = True  # the robot always counts
        step = float(np.max(poses.motion(previous, radii)[moved], initial=0.0))
        margin = self.config.sto.weld_margin + step
        watched = {int(b.index()) for b, m in zip(self._watched, moved) if m}
        near = set()
        for pair in self._query.Eval(self._world_context).ComputeSignedDistancePairwiseClosestPoints(margin):
            a, b = self._geometry_body[pair.id_A], self._geometry_body[pair.id_B]
            for welded, other in ((a, b), (b, a)):
                if welded in self._welded_bodies and other in watched:
                    near.add(self._welded_bodies[welded])
        return tuple(obj.name for obj in self.scene.objects if obj.name in near)

    def read(self) -> tuple[np.ndarray, np.ndarray, float, bool, str | None]:
        """The current object positions, tcp position, largest contact force on an object, whether
        the robot touches the table, and why the simulation is not to be trusted (None if sane)."""
        plant, context = self.plant, self._plant_context
        positions = np.array([body.EvalPoseInWorld(context).translation() for body in self._objects])
        speeds = [np.linalg.norm(body.EvalSpatialVelocityInWorld(context).translational()) for body in self._objects]
        tcp = self._tcp.CalcPoseInWorld(context).translation()
        results = plant.get_contact_results_output_port().Eval(context)
        max_force, table_contact = 0.0, False
        for i in range(results.num_point_pair_contacts()):
            info = results.point_pair_contact_info(i)
            a, b = int(info.bodyA_index()), int(info.bodyB_index())
            if a in self._object_bodies or b in self._object_bodies:
                max_force = max(max_force, float(np.linalg.norm(info.contact_force())))
            if (a in self._robot_bodies and b in self._table_bodies) or (b in self._robot_bodies and a in self._table_bodies):
                table_contact = True
        problem = None
        sto = self.config.sto
        table = self.scene.table
        if not (np.all(np.isfinite(positions)) and np.all(np.isfinite(tcp))):
            return positions, tcp, max_force, table_contact, "a position is not finite"
        # Objects pushed off the edge fall freely (a legitimate outcome); only objects over the table
        # are checked for impossible speeds and for sinking into it.
        over = over_table_mask(positions, table)
        speeds = np.where(over, speeds, 0.0)
        sunk = over & (positions[:, 2] < table.height - sto.max_sink)  # a centre inside the table top
        if np.max(speeds) > sto.max_object_speed:
            name = self.scene.objects[int(np.argmax(speeds))].name
            problem = f"{name} moves at {np.max(speeds):.1f} m/s over the table (limit {sto.max_object_speed} m/s)"
        elif np.any(sunk):
            problem = f"{self.scene.objects[int(np.argmax(sunk))].name} sank into the table"
        return positions, tcp, max_force, table_contact, problem

    def simulate(self, sequence: ControlSequence) -> RolloutSamples:
        """Roll ``sequence`` out from the initial state and read the state every sample period (on a
        reduced world, up to the first sample at which something came near a welded object)."""
        own = self.welded_objects
        return sample_rollout(sequence, self.config.sto, {own: self}.get, lambda t: own)

    def cost(self, samples: RolloutSamples, sequence: ControlSequence) -> RolloutOutcome:
        """The cost of ``sequence``'s rollout from its ``samples``.

        Raises:
            ValueError: the samples stopped because something came near a welded object.
        """
        if samples.touched:
            raise ValueError(f"the rollout came near the welded {', '.join(samples.touched)}")
        return rollout_cost(samples, self.scene, self.config.sto, tcp_height=self._tcp_height,
                            effort=sequence.effort(), step_duration=float(np.mean(sequence.steps)))

    def rollout(self, sequence: ControlSequence) -> RolloutOutcome:
        """Simulate ``sequence`` and cost it (see ``cost``)."""
        return timed_rollout(sequence, self.simulate, self)


def timed_rollout(sequence: ControlSequence, simulate, costing: RolloutWorld) -> RolloutOutcome:
    """``simulate(sequence)`` costed by ``costing``, with the welding record and the wall time."""
    started = time.perf_counter()
    samples = simulate(sequence)
    outcome = replace(costing.cost(samples, sequence), welded=samples.welded, switches=samples.switches)
    return replace(outcome, wall_s=time.perf_counter() - started)


def sample_rollout(sequence: ControlSequence, sto: StoConfig, world_for, welded_at) -> RolloutSamples:
    """Roll ``sequence`` out and read the state every ``sto.sample_period``, on worlds of one scene
    with fewer and fewer objects welded.

    Args:
        world_for: ``world_for(welded)``, the ``RolloutWorld`` with the objects ``welded`` welded, or
            None if there is none (the samples then stop where it would be needed).
        welded_at: ``welded_at(t)``, the objects to keep welded from sample time ``t`` on (at most
            those welded before: an object once free stays free).

    At every sample the rollout moves on to a world with fewer objects welded (carrying over the
    robot's and the free objects' states) when ``welded_at`` frees some, and goes back to the
    previous sample and on with them freed when the robot or an object that has moved came near a
    welded object (``RolloutWorld.near_welded``): until then nothing can have touched it, so in the
    full model it would have stayed at rest, as it does welded.
    """
    end = sequence.duration + sto.settle_s
    count = max(1, math.ceil(end / sto.sample_period - 1e-9))
    times = np.minimum(sto.sample_period * np.arange(count + 1), end)
    welded = frozenset(welded_at(0.0))
    world = world_for(welded)
    world.begin(sequence)
    start = previous = world.watched_poses()
    readings: list[list] = []
    problem, touched, switches = None, (), 0
    saved: tuple[float, dict] | None = None  # the time and the states at the last sample read
    k = 0
    while k < len(times):
        t = times[k]
        if t > world.time():
            problem = world.advance_to(t)
            if problem is not None:
                break
        poses = world.watched_poses() if welded else previous  # nothing to watch for once all are free
        near = world.near_welded(poses, previous, start)
        if near:  # back to the previous sample (or the start) with those objects freed
            freed, at = frozenset(near), saved
        else:
            *reading, problem = world.read()
            readings.append(reading)
            if problem is not None:
                problem = f"{problem} at t = {t:.2f} s"
                break
            previous, saved = poses, (float(t), world.states()) if welded else None
            freed, at = welded - frozenset(welded_at(t)), saved
            k += 1
        if freed:
            successor = world_for(welded - freed)
            if successor is None:
                touched = tuple(sorted(freed))
                break
            world, welded, switches = successor, welded - freed, switches + 1
            if at is None:
                world.begin(sequence)
            else:
                world.begin(sequence, time=at[0], states=at[1])
    positions, tcps, forces, contacts = zip(*readings) if readings else ([], [], [], [])
    return RolloutSamples(times[: len(readings)], np.array(positions), np.array(tcps), np.array(forces),
                          np.array(contacts, dtype=bool), problem, touched, welded=tuple(sorted(welded)),
                          switches=switches)


class SceneRollouts:
    """Rollouts on one scene: on the full world, or with ``sto.reduced_model`` on reduced worlds
    (see the module's docstring), built on first use and the latest ``worlds_kept`` kept.

    A rollout's outcome is a pure function of the scene, the configuration and the sequence: which
    objects are welded when follows from the sequence alone, whichever worlds happen to be built.
    """

    def __init__(self, scene: Scene, config: WorldConfig | None = None, *, worlds_kept: int = 32) -> None:
        self.full = RolloutWorld(scene, config)
        self.scene, self.config = scene, self.full.config
        self._worlds_kept = worlds_kept
        self._reduced: OrderedDict[frozenset[str], RolloutWorld] = OrderedDict()

    @property
    def start_collisions(self) -> tuple[str, ...]:
        return self.full.start_collisions

    def world(self, welded: frozenset[str]) -> RolloutWorld:
        """The world with the objects ``welded`` welded (the full one when empty)."""
        if not welded:
            return self.full
        if welded not in self._reduced:
            self._reduced[welded] = RolloutWorld(self.scene, self.config, welded_objects=welded)
            while len(self._reduced) > self._worlds_kept:
                self._reduced.popitem(last=False)
        self._reduced.move_to_end(welded)
        return self._reduced[welded]

    def weld_schedule(self, sequence: ControlSequence):
        """``welded_at(t)``: the objects the robot's commanded motion does not come within
        ``sto.weld_clearance`` of before ``t + sto.weld_lookahead`` (none with the reduced model off)."""
        sto = self.config.sto
        if not sto.reduced_model:
            return lambda t: frozenset()
        approach = self.full.approach_times(sequence, sto.weld_clearance)
        return lambda t: frozenset(name for name, first in approach.items() if first > t + sto.weld_lookahead)

    def simulate(self, sequence: ControlSequence) -> RolloutSamples:
        """Roll ``sequence`` out on the reduced worlds (or the full one), reading the state every sample period."""
        return sample_rollout(sequence, self.config.sto, self.world, self.weld_schedule(sequence))

    def rollout(self, sequence: ControlSequence) -> RolloutOutcome:
        """Simulate ``sequence`` and cost it."""
        return timed_rollout(sequence, self.simulate, self.full)
