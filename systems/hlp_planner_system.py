"""``HlpPlannerSystem``: the human-like planner as a Drake LeafSystem (scene in, HighLevelPlan out)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.math import RigidTransform
from pydrake.multibody.plant import MultibodyPlant
from pydrake.systems.framework import Context, LeafSystem

from hlp_drake.learners.bundled import default_models
from hlp_drake.learners.models import DecisionModels
from hlp_drake.planner import HighLevelPlan, PlannerConfig, plan
from hlp_drake.scene.generators import generate_scene
from hlp_drake.scene.model import Scene

POSE_RESOLUTION = 1e-3  # m; object poses closer than this to the last planned ones reuse the plan


class HlpPlannerSystem(LeafSystem):
    """Plans with the human-like planner whenever the scene it sees changes.

    Input ports:
        scene: an abstract ``Scene`` (used when connected or fixed).
        body_poses: the plant's ``body_poses`` output (declared when ``plant`` and ``template``
            are given); object poses are read from the bodies named after the template's objects.

    Output ports:
        plan: an abstract ``HighLevelPlan``. It is cached by Drake on its input, and the planner
            runs again only when an object moved by more than ``POSE_RESOLUTION``.

    Args:
        models: decision models (default: the bundled ones).
        config: planner settings (default: the models' mode).
        plant, template: to plan from the plant's body poses, the plant and the scene whose
            objects (by name) it simulates.
    """

    def __init__(self, *, models: DecisionModels | None = None, config: PlannerConfig | None = None,
                 plant: MultibodyPlant | None = None, template: Scene | None = None) -> None:
        super().__init__()
        self._models = models or default_models()
        self._config = config or PlannerConfig(mode=self._models.mode)
        self._template = template
        self._last: tuple[tuple, HighLevelPlan] | None = None
        self.plans_computed = 0
        self._scene_port = self.DeclareAbstractInputPort(name="scene", model_value=AbstractValue.Make(generate_scene("vr", 0)))
        self._poses_port = None
        self._bodies: dict[str, int] = {}
        if plant is not None or template is not None:
            if plant is None or template is None:
                raise ValueError("planning from body poses needs both plant and template")
            self._bodies = {o.name: int(plant.GetBodyByName(o.name).index()) for o in template.objects}
            self._poses_port = self.DeclareAbstractInputPort(
                name="body_poses", model_value=AbstractValue.Make([RigidTransform()]))
        self._plan_port = self.DeclareAbstractOutputPort(
            name="plan", alloc=lambda: AbstractValue.Make(HighLevelPlan("", ())), calc=self._calc_plan,
            prerequisites_of_calc={self.all_input_ports_ticket()})

    def get_scene_input_port(self):
        return self._scene_port

    def get_body_poses_input_port(self):
        return self._poses_port

    def get_plan_output_port(self):
        return self._plan_port

    def _scene(self, context: Context) -> Scene:
        if self._scene_port.HasValue(context):
            return self._scene_port.Eval(context)
        if self._poses_port is None or not self._poses_port.HasValue(context):
            raise RuntimeError("HlpPlannerSystem: connect or fix its 'scene' or 'body_poses' input")
        poses = self._poses_port.Eval(context)

        def moved(obj):
            pose = poses[self._bodies[obj.name]]
            x, y, _ = pose.translation()
            yaw = float(pose.rotation().ToRollPitchYaw().yaw_angle())
            return replace(obj, x=float(x), y=float(y), yaw=yaw)

        template = self._template
        return replace(template, target=moved(template.target), obstacles=tuple(moved(o) for o in template.obstacles))

    def _calc_plan(self, context: Context, output: AbstractValue) -> None:
        scene = self._scene(context)
        key = (scene.name, scene.table, scene.start,
               tuple(tuple(np.round(np.array([o.x, o.y, o.yaw]) / POSE_RESOLUTION).astype(int)) for o in scene.objects))
        if self._last is None or self._last[0] != key:
            self._last = (key, plan(scene, self._models, self._config))
            self.plans_computed += 1
        output.set_value(self._last[1])
