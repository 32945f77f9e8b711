"""The robot that ``measure_reach.py`` measures: one arm on a continuous plant, for IK and collisions.

A development module, never imported by ``hlp_drake`` at run time; ``measure_reach.py`` imports it
from the folder both sit in. ``Arm`` builds the robot (a model of ``make_arms.py`` welded to the
world by its pedestal, or the mobile UR5 with its base held at the origin) with an optional table
top in front of it, holds everything but the arm's joints fixed (fingers open), and keeps one
InverseKinematics program that puts the tcp at a point with its z along world +x and its y
horizontal; it grades solutions by collisions and bounds what the arm can reach at all.
"""

from __future__ import annotations

import itertools
import math

import make_arms
import numpy as np
from pydrake.geometry import Box, GeometryId
from pydrake.math import RigidTransform
from pydrake.multibody.inverse_kinematics import InverseKinematics
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph, CoulombFriction, MultibodyPlant
from pydrake.solvers import SnoptSolver
from pydrake.systems.framework import DiagramBuilder

ANGLE_TOLERANCE = 0.2  # rad: tcp z from world +x, tcp y from the horizontal
POSITION_TOLERANCE = 1e-4  # m
TABLE_EDGE = 0.20  # the table's front edge in front of the pedestal's axis, m

# Hand-picked postures of the arm (7 or 6 joints) near "gripper forward and horizontal".
NOMINAL = {
    "panda": [
        (0.0, 0.3, 0.0, -2.0, 0.0, 2.3, 0.785),
        (0.0, -0.3, 0.0, -2.6, 0.0, 3.5, 0.785),
        (0.0, 0.9, 0.0, -1.0, 0.0, 1.9, 0.785),
        (0.0, -0.6, 0.0, -2.8, 0.0, 2.2, -0.785),
    ],
    "iiwa14": [
        (0.0, 0.6, 0.0, -1.4, 0.0, -0.8, 0.0),
        (0.0, 1.2, 0.0, -0.6, 0.0, -0.8, 0.0),
        (0.0, 0.0, 0.0, -2.0, 0.0, -0.5, 0.0),
        (0.0, -0.4, 0.0, -1.9, 0.0, 0.9, 0.0),
    ],
    "ur5": [
        (0.0, -0.9, 1.9, -1.0, 1.57, -1.57),
        (0.0, -0.3, 0.6, -0.3, 1.57, -1.57),
        (0.0, -1.6, 2.6, -1.0, 1.57, -1.57),
        (0.0, -2.0, 2.4, -0.4, 1.57, -1.57),
    ],
}
FLANGES = {"panda": "panda_flange", "iiwa14": "iiwa_flange", "ur5": "ur5_flange"}


class Arm:
    """One robot on a continuous plant with its scene graph, for IK and collision checks."""

    def __init__(
        self,
        name: str,
        mount: float,
        table_top: float | None = None,
        angle_tolerance: float = ANGLE_TOLERANCE,
    ) -> None:
        """``name`` on a pedestal ``mount`` high (the mobile UR5 has its own riser); with
        ``table_top``, a table top in front of the pedestal: its front edge ``TABLE_EDGE`` from the
        pedestal's axis, its top ``table_top`` above the floor."""
        self.name, self.angle_tolerance = name, angle_tolerance
        builder = DiagramBuilder()
        plant, scene_graph = AddMultibodyPlantSceneGraph(builder, time_step=0.0)
        arm_joints = self._add_robot(plant, mount)
        self.table = None if table_top is None else self._add_table(plant, table_top)
        plant.Finalize()
        self.plant, self.scene_graph = plant, scene_graph
        self.diagram = builder.Build()
        self.context = self.diagram.CreateDefaultContext()
        self.plant_context = plant.GetMyContextFromRoot(self.context)
        self.sg_context = scene_graph.GetMyContextFromRoot(self.context)
        joints = [plant.GetJointByName(n) for n in arm_joints]
        self.arm_index = np.array([j.position_start() for j in joints])
        self.lower = plant.GetPositionLowerLimits()
        self.upper = plant.GetPositionUpperLimits()
        # Everything but the arm is held: fingers open, the mobile base at the origin.
        self.fixed = np.zeros(plant.num_positions())
        for joint_index in plant.GetJointIndices():
            joint = plant.get_joint(joint_index)
            if joint.num_positions() == 1 and "finger" in joint.name():
                self.fixed[joint.position_start()] = joint.position_upper_limits()[0]
        self.tcp = plant.GetFrameByName("tcp")
        self._add_ik(angle_tolerance)
        self.solver = SnoptSolver()
        self._bound_reach(joints)
        self.rng = np.random.default_rng(0)
        self.nominal = [np.array(n) for n in NOMINAL[name]]

    def _add_robot(self, plant: MultibodyPlant, mount: float) -> tuple[str, ...]:
        """Add the robot to ``plant``, set ``axis`` (its pedestal's or riser's, in the world's xy) and
        ``mount``; return the names of the arm's joints."""
        if self.name == "ur5":
            from make_mobile_ur5 import ARM_MOUNT_XYZ

            from hlp_drake.systems.world.robot import add_robot
            from hlp_drake.systems.world.robot_description import MOBILE_UR5

            add_robot(plant, MOBILE_UR5)
            self.axis = np.array(ARM_MOUNT_XYZ[:2])
            self.mount = ARM_MOUNT_XYZ[2]
            return MOBILE_UR5.arm_joints
        from pydrake.multibody.parsing import Parser

        text = make_arms.panda_urdf(mount) if self.name == "panda" else make_arms.iiwa14_urdf(mount)
        Parser(plant).AddModelsFromString(text, "urdf")
        plant.WeldFrames(plant.world_frame(), plant.GetFrameByName(f"{self.name}_pedestal"))
        self.axis = np.zeros(2)
        self.mount = mount
        spec = make_arms.PANDA_JOINTS if self.name == "panda" else make_arms.IIWA_JOINTS
        return tuple(joint[0] for joint in spec)

    def _add_table(self, plant: MultibodyPlant, table_top: float) -> GeometryId:
        """The table top's collision geometry: its front edge ``TABLE_EDGE`` in front of the axis,
        its top ``table_top`` above the floor."""
        size = (2.0, 4.0, 0.05)
        centre = (self.axis[0] + TABLE_EDGE + size[0] / 2, self.axis[1], table_top - size[2] / 2)
        return plant.RegisterCollisionGeometry(
            plant.world_body(), RigidTransform(centre), Box(*size), "table", CoulombFriction(0.5, 0.5)
        )

    def _add_ik(self, angle_tolerance: float) -> None:
        """The IK program: every joint but the arm's held at ``fixed``; the tcp at a point (``solve``
        sets it), its z within ``angle_tolerance`` of world +x, its y as near the horizontal."""
        plant = self.plant
        self.ik = InverseKinematics(plant, self.plant_context, with_joint_limits=True)
        q = self.ik.q()
        free = np.zeros(plant.num_positions(), dtype=bool)
        free[self.arm_index] = True
        for i in np.flatnonzero(~free):
            self.ik.prog().AddBoundingBoxConstraint(self.fixed[i], self.fixed[i], q[i])
        world = plant.world_frame()
        self.position = self.ik.AddPositionConstraint(
            self.tcp, [0, 0, 0], world, [0, 0, 0], [0, 0, 0]
        ).evaluator()
        self.approach = self.ik.AddAngleBetweenVectorsConstraint(
            self.tcp, [0, 0, 1], world, [1, 0, 0], 0.0, angle_tolerance
        ).evaluator()
        self.level = self.ik.AddAngleBetweenVectorsConstraint(
            self.tcp,
            [0, 1, 0],
            world,
            [0, 0, 1],
            math.pi / 2 - angle_tolerance,
            math.pi / 2 + angle_tolerance,
        ).evaluator()

    def _bound_reach(self, joints: list) -> None:
        """A sure bound: the flange is at most the sum of the joint-to-joint distances from joint 1's
        origin (fixed to the base), and the tcp ``tool`` along its z from the flange."""
        plant = self.plant
        plant.SetPositions(self.plant_context, self.fixed)
        origins = [j.frame_on_child().CalcPoseInWorld(self.plant_context).translation() for j in joints]
        flange = plant.GetFrameByName(FLANGES[self.name]).CalcPoseInWorld(self.plant_context).translation()
        origins.append(flange)
        self.start = origins[0]
        self.stretch = sum(np.linalg.norm(b - a) for a, b in itertools.pairwise(origins))
        self.tool = float(np.linalg.norm(self.tcp.CalcPoseInWorld(self.plant_context).translation() - flange))

    def may_reach(self, p: np.ndarray) -> bool:
        """False if ``p`` is surely out of reach with the tcp within ANGLE_TOLERANCE of +x."""
        wrist = p - self.tool * np.array([1.0, 0.0, 0.0])
        slack = 2.0 * self.tool * math.sin(ANGLE_TOLERANCE / 2.0) + 1e-3
        return bool(np.linalg.norm(wrist - self.start) <= self.stretch + slack)

    def full(self, q_arm: np.ndarray) -> np.ndarray:
        q = self.fixed.copy()
        q[self.arm_index] = q_arm
        return q

    def solve(self, p: np.ndarray, seed: np.ndarray) -> np.ndarray | None:
        """Arm joints putting the tcp at world point ``p`` (horizontal, along +x), or None."""
        self.position.set_bounds(p - POSITION_TOLERANCE, p + POSITION_TOLERANCE)
        result = self.solver.Solve(self.ik.prog(), self.full(seed), None)
        if not result.is_success():
            return None
        q = result.GetSolution(self.ik.q())
        if not self.satisfied(q, p):
            return None
        return q[self.arm_index]

    def satisfied(self, q: np.ndarray, p: np.ndarray) -> bool:
        if np.any(q < self.lower - 1e-6) or np.any(q > self.upper + 1e-6):
            return False
        self.plant.SetPositions(self.plant_context, q)
        X = self.tcp.CalcPoseInWorld(self.plant_context)
        R = X.rotation().matrix()
        tol = self.angle_tolerance
        ok_pose = np.all(np.abs(X.translation() - p) <= POSITION_TOLERANCE + 1e-6)
        # Cosines, as the constraints hold them (to the solver's feasibility tolerance).
        ok_approach = R[0, 2] >= math.cos(tol) - 1e-6  # tcp z . world x
        ok_level = abs(R[2, 1]) <= math.sin(tol) + 1e-6  # tcp y . world z
        return bool(ok_pose and ok_approach and ok_level)

    def grade(self, q_arm: np.ndarray) -> int:
        """2 if the robot at ``q_arm`` touches neither itself (arm, gripper, pedestal) nor the table,
        1 if it touches the table only, 0 if it collides with itself."""
        self.plant.SetPositions(self.plant_context, self.full(q_arm))
        query = self.scene_graph.get_query_output_port().Eval(self.sg_context)
        pairs = query.ComputePointPairPenetration()
        if any(self.table not in (pair.id_A, pair.id_B) for pair in pairs):
            return 0
        return 1 if pairs else 2

    def random_seed(self) -> np.ndarray:
        lo, hi = self.lower[self.arm_index], self.upper[self.arm_index]
        lo, hi = np.maximum(lo, -math.pi), np.minimum(hi, math.pi)
        return self.rng.uniform(lo, hi)
