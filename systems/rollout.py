"""One STO rollout: a control sequence simulated with contact in the world, and its cost.

``RolloutWorld(scene, config)`` builds the world diagram once (``make_world_diagram`` at the rollout
time step ``config.sto.rollout_time_step``) with a C++ ``TrajectorySource`` driving the robot, and
keeps the initial context. ``rollout(sequence)`` swaps the source's trajectory, resets the context and
simulates; Python only reads the state every ``config.sto.sample_period`` seconds for the cost.

The cost (``StoCost``) is computed by ``rollout_cost`` from the sampled states (``RolloutSamples``),
a pure function: goal distance at the end, objects off the table, robot-table contact, high contact
forces on objects, disturbance of the obstacles and of the target, ending next to an obstacle, and
the control effort.
"""

from __future__ import annotations

import copy
import math
import time
from dataclasses import dataclass, replace

import numpy as np
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder

from hlp_drake.scene.model import Scene
from hlp_drake.systems.control_sequence import ControlSequence
from hlp_drake.systems.robot import TCP_FRAME
from hlp_drake.systems.scene_models import TABLE_NAME, object_body, off_table_mask, over_table_mask
from hlp_drake.systems.sto_config import StoConfig
from hlp_drake.systems.world import add_position_trajectory, make_world_diagram, tcp_keypoint_height, world_plant
from hlp_drake.systems.world_config import WorldConfig

BLOWN_UP_COST = 1.0e9
"""Cost of a rollout whose simulation failed or blew up (ranked below every sane one)."""


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
    """

    times: np.ndarray
    positions: np.ndarray
    tcp: np.ndarray
    max_force: np.ndarray
    table_contact: np.ndarray
    blew_up: str | None = None


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
    """

    cost: float
    terms: dict[str, float]
    success: bool
    failure_reason: str | None
    target_distance: float
    fallen: tuple[str, ...] = ()
    simulated_s: float = 0.0
    wall_s: float = 0.0


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


class RolloutWorld:
    """A pre-built world for rolling out control sequences on one scene (one per worker process)."""

    def __init__(self, scene: Scene, config: WorldConfig | None = None) -> None:
        config = WorldConfig() if config is None else config
        self.scene = scene
        self.config = config
        builder = DiagramBuilder()
        world = builder.AddSystem(make_world_diagram(scene, rollout_world_config(config)))
        plant, robot = world_plant(world)
        start = plant.GetPositions(plant.CreateDefaultContext(), robot)
        hold = ControlSequence(np.array([0.0, 1.0]), np.vstack([start, start])).to_trajectory()
        self._source = add_position_trajectory(builder, world, hold)
        self.diagram = builder.Build()
        self.plant, self.robot = plant, robot
        self.start_positions = start
        self._simulator = Simulator(self.diagram)
        self._context = self._simulator.get_mutable_context()
        self._plant_context = plant.GetMyMutableContextFromRoot(self._context)
        self._initial = self._context.Clone()
        self._objects = [object_body(plant, obj.name) for obj in scene.objects]
        self._object_bodies = {int(body.index()) for body in self._objects}
        self._table_bodies = {int(i) for i in plant.GetBodyIndices(plant.GetModelInstanceByName(TABLE_NAME))}
        self._robot_bodies = {int(i) for i in plant.GetBodyIndices(robot)}
        self._tcp = plant.GetFrameByName(TCP_FRAME, robot)
        self._tcp_height = tcp_keypoint_height(scene, config)
        self.start_collisions = self._start_collisions(world)

    def _start_collisions(self, world) -> tuple[str, ...]:
        """Names of the bodies the robot penetrates in the initial state."""
        query = world.GetOutputPort("query_object").Eval(world.GetMyContextFromRoot(self._context))
        inspector = query.inspector()
        hits = set()
        for pair in query.ComputePointPairPenetration():
            a, b = (self.plant.GetBodyFromFrameId(inspector.GetFrameId(g)) for g in (pair.id_A, pair.id_B))
            a_robot, b_robot = int(a.index()) in self._robot_bodies, int(b.index()) in self._robot_bodies
            if a_robot != b_robot:
                hits.add((b if a_robot else a).name())
        return tuple(sorted(hits))

    def _sample(self) -> tuple[np.ndarray, np.ndarray, float, bool, str | None]:
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
        """Roll ``sequence`` out from the initial state and read the state every sample period."""
        sto = self.config.sto
        self._source.UpdateTrajectory(sequence.to_trajectory())
        self._context.SetTimeStateAndParametersFrom(self._initial)
        self._simulator.Initialize()
        end = sequence.duration + sto.settle_s
        count = max(1, math.ceil(end / sto.sample_period - 1e-9))
        times = np.minimum(sto.sample_period * np.arange(count + 1), end)
        positions, tcps, forces, contacts = [], [], [], []
        problem = None
        for t in times:
            if t > self._context.get_time():
                try:
                    self._simulator.AdvanceTo(float(t))
                except RuntimeError as error:
                    problem = f"the solver failed at t = {self._context.get_time():.2f} s: {str(error).splitlines()[0]}"
                    break
            p, tcp, force, contact, problem = self._sample()
            positions.append(p)
            tcps.append(tcp)
            forces.append(force)
            contacts.append(contact)
            if problem is not None:
                problem = f"{problem} at t = {t:.2f} s"
                break
        n = len(positions)
        return RolloutSamples(times[:n], np.array(positions), np.array(tcps), np.array(forces),
                              np.array(contacts, dtype=bool), problem)

    def rollout(self, sequence: ControlSequence) -> RolloutOutcome:
        """Simulate ``sequence`` and cost it."""
        started = time.perf_counter()
        samples = self.simulate(sequence)
        outcome = rollout_cost(samples, self.scene, self.config.sto, tcp_height=self._tcp_height,
                               effort=sequence.effort(), step_duration=float(np.mean(sequence.steps)))
        return replace(outcome, wall_s=time.perf_counter() - started)
