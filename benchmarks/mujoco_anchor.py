"""MuJoCo beside Drake: CPU seconds per simulated second of the same scene and the same sequences.

    python benchmarks/mujoco_anchor.py [--out DIR] [--rollouts 8] [--repeats 3] [--steps 0.002 0.005 0.02]

An outside anchor for the rollout cost ``sto.py`` measures: the throughput scene and its noisy 3 s
sequences (``sto.throughput_sequences``) rolled out in MuJoCo at each ``--steps`` time step and in
Drake on the execution model the optimiser rolls out on (``RolloutWorld``, every object
awake) and on the execution model before issue 39 (``physics_models.MODELS["full_2ms"]``: 2 ms, the
full contact geometry), the models interleaved in each of
``--repeats`` passes. CPU time (``time.process_time``, one core) per rollout and per simulated
second; the Drake / MuJoCo ratios are paired per pass and their medians reported. A sanity check
goes with it: per sequence, how many objects end more than 1 cm from their start in each model, how
far each model's robot ends from the execution model's, and how far the objects drift in 3 s with
the robot holding its start pose.

The MuJoCo model is converted from the finalized Drake plant of the scenario's world
(``make_world_diagram``, ``mjcf.mjcf_from_plant``): the same bodies, masses, inertias, joint tree and
limits, the same collision shapes (one geom per Drake collision geometry, support spheres included)
and friction coefficients, the same collision filters, PD position actuators with Drake's gains and
effort limits (the command ``q_d + kd / kp * v_d`` makes MuJoCo's ``kp (ctrl - q) - kv v`` Drake's
``kp (q_d - q) + kd (v_d - v)``), gravity compensation through the actuators and the mimic finger
as an equality constraint. It is a comparable model, not an identical one: MuJoCo's soft contact
keeps its default solver parameters (not Drake's point stiffness and dissipation), combines two
friction coefficients by their maximum (Drake: 2 a b / (a + b)), integrates the actuators' stiffness
explicitly (Drake's SAP: implicitly) and runs with its default solver settings, the ``implicitfast``
integrator aside (``mjcf.INTEGRATOR``).
The Drake times include each rollout's state sampling and costing (MuJoCo's: computing the commands
and the stepping loop). The optimiser's reduced model (objects asleep, ``SceneRollouts``) is not
timed here.
Writes ``DIR/mujoco_anchor.json``, ``DIR/mujoco_anchor.png`` and the model, ``DIR/mujoco_anchor.xml``.
"""

from __future__ import annotations

import argparse
import importlib.metadata
import json
import os
import platform
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import NamedTuple

import numpy as np
from mjcf import INTEGRATOR, mjcf_from_plant, mujoco_names, mujoco_qpos, urdf_couplers
from physics_models import MODELS
from sto import HORIZON, throughput_sequences
from tqdm import tqdm

from hlp_drake.commands.parsing import run_cli
from hlp_drake.files.atomic import atomic_path, check_folder, write_text_atomic
from hlp_drake.systems.low_level.control_sequence import ControlSequence
from hlp_drake.systems.low_level.sto.rollout_world import RolloutWorld
from hlp_drake.systems.low_level.sto.spec import RolloutSpec
from hlp_drake.systems.scenario import Scenario
from hlp_drake.systems.world.robot_description import MOBILE_UR5, models_directory
from hlp_drake.systems.world.world import make_world_diagram, world_plant

try:
    import mujoco
except ImportError:  # an optional extra: main() says so
    mujoco = None

MISSING = "error: mujoco is not installed (pip install -e '.[bench]')"
MOVED = 0.01
"""An object counts as moved when its centre ends more than this far from its start, m."""
ROBOT_URDF = models_directory() / "robot" / "mobile_ur5.urdf"


class Run(NamedTuple):
    """One rollout: its CPU time and simulated time (s), how far each object's centre ended from its
    start (m), whether the simulation failed, and the robot's positions at the end."""

    cpu_s: float
    simulated_s: float
    drift: np.ndarray
    failed: bool
    robot_end: np.ndarray

    @property
    def moved(self) -> int:
        """How many objects ended more than ``MOVED`` from their start."""
        return int(np.sum(self.drift > MOVED))


class MujocoWorld:
    """The scenario's world (``make_world_diagram``; ``world``, ``plant``, ``robot``, ``inspector``)
    converted to MuJoCo (``xml``, ``model``, ``data``), driven by control sequences."""

    def __init__(self, scenario: Scenario) -> None:
        self.world = world = make_world_diagram(scenario, cameras=False)
        self.inspector = world.GetSubsystemByName("scene_graph").model_inspector()
        self.plant, self.robot = plant, robot = world_plant(world)
        compensated = (robot,) if scenario.controller.gravity_compensation else ()
        couplers = urdf_couplers(ROBOT_URDF)
        if len(couplers) != plant.num_constraints():
            raise RuntimeError("the plant has constraints besides the robot's mimic joints")
        self.xml = mjcf_from_plant(
            plant, self.inspector, time_step=0.005, couplers=couplers, gravity_compensated=compensated
        )
        self.model = mujoco.MjModel.from_xml_string(self.xml)
        self.data = mujoco.MjData(self.model)
        context = plant.CreateDefaultContext()
        self.qpos0 = mujoco_qpos(plant, context, self.model)
        # the robot's positions (a ControlSequence's columns) as MuJoCo qpos addresses
        joints, names = mujoco_names(plant, "joint")
        robot_joints = sorted(
            (j.position_start(), name)
            for j, name in zip(joints, names)
            if j.model_instance() == robot and j.num_positions() > 0
        )
        column = {name: c for c, (_, name) in enumerate(robot_joints)}
        self.robot_qpos = np.array([self.model.jnt_qposadr[self.model.joint(n).id] for _, n in robot_joints])
        actuated = [self.model.joint(self.model.actuator_trnid[a, 0]).name for a in range(self.model.nu)]
        self.columns = np.array([column[name] for name in actuated])
        gains, bias = self.model.actuator_gainprm[:, 0], -self.model.actuator_biasprm[:, 2]
        self.lead = bias / gains
        """kd / kp per actuator: the command q_d + lead v_d gives Drake's PD (the module's docstring)."""
        self.object_qpos = np.array(
            [self.model.jnt_qposadr[self.model.body(obj.name).jntadr[0]] for obj in scenario.scene.objects]
        )[:, None] + np.arange(3)
        self.object_start = self.qpos0[self.object_qpos]

    def controls(self, sequence: ControlSequence, time_step: float) -> np.ndarray:
        """(steps, actuators) commands of ``sequence`` at the start of every step."""
        times = time_step * np.arange(round(sequence.duration / time_step))
        trajectory = sequence.to_trajectory()
        q = trajectory.vector_values(times)[self.columns]
        v = trajectory.MakeDerivative().vector_values(times)[self.columns]
        return (q + self.lead[:, None] * v).T

    def rollout(self, sequence: ControlSequence, time_step: float) -> Run:
        """Simulate ``sequence`` from the scene's start at ``time_step``."""
        model, data = self.model, self.data
        cpu = time.process_time()
        model.opt.timestep = time_step
        mujoco.mj_resetData(model, data)
        data.qpos[:] = self.qpos0
        commands = self.controls(sequence, time_step)
        for command in commands:
            data.ctrl[:] = command
            mujoco.mj_step(model, data)
        cpu = time.process_time() - cpu
        failed = data.warning[mujoco.mjtWarning.mjWARN_BADQACC].number > 0 or not np.all(
            np.isfinite(data.qpos)
        )
        return Run(
            cpu_s=cpu,
            simulated_s=len(commands) * time_step,
            drift=np.linalg.norm(data.qpos[self.object_qpos] - self.object_start, axis=1),
            failed=bool(failed),
            robot_end=data.qpos[self.robot_qpos].copy(),
        )


class DrakeModel:
    """A ``RolloutWorld`` of the scenario."""

    def __init__(self, scenario: Scenario) -> None:
        self.world = RolloutWorld(RolloutSpec.of(scenario))
        self.object_start = self.world.object_positions()  # the initial state, before any rollout
        self.time_step = self.world.spec.model.plant.time_step

    def rollout(self, sequence: ControlSequence) -> Run:
        cpu = time.process_time()
        outcome = self.world.rollout(sequence)
        cpu = time.process_time() - cpu
        return Run(
            cpu_s=cpu,
            simulated_s=self.world.time(),
            drift=np.linalg.norm(self.world.object_positions() - self.object_start, axis=1),
            failed="blew_up" in outcome.terms,
            robot_end=self.world.states()[MOBILE_UR5.name][: len(self.world.start_positions)],
        )


@dataclass(frozen=True)
class Models:
    """The timed models by name: MuJoCo at each step, then Drake's execution model and the former one."""

    runners: dict
    drake: dict[str, DrakeModel]
    mujoco: MujocoWorld

    @classmethod
    def build(cls, scenario: Scenario, steps: tuple[float, ...]) -> Models:
        world = MujocoWorld(scenario)
        drake = {}
        for kind, config in (("execution", scenario), ("former", scenario.updated(MODELS["full_2ms"]))):
            model = DrakeModel(config)
            drake[f"drake_{kind}_{model.time_step * 1000:g}ms"] = model
        runners = {f"mujoco_{s * 1000:g}ms": (lambda seq, s=s: world.rollout(seq, s)) for s in steps}
        runners.update({name: model.rollout for name, model in drake.items()})
        return cls(runners, drake, world)


def idle_check(models: Models, horizon: float) -> dict:
    """Every model with the robot holding its start pose for ``horizon`` s: the objects' largest drift
    (mm) and how many moved more than ``MOVED``."""
    start = next(iter(models.drake.values())).world.start_positions
    hold = ControlSequence(np.array([0.0, horizon]), np.vstack([start, start]))
    result = {}
    for name, rollout in models.runners.items():
        run = rollout(hold)
        result[name] = {
            "max_drift_mm": float(np.max(run.drift) * 1000),
            "moved": run.moved,
            "failed": run.failed,
        }
    return result


def measure(models: Models, sequences: list[ControlSequence], repeats: int) -> list[dict]:
    """``repeats`` passes, each rolling every sequence out on every model (the models' order turned
    by one each pass), after one warm-up rollout per model."""
    names = list(models.runners)
    for name in names:
        models.runners[name](sequences[0])
    passes = []
    for p in tqdm(range(repeats), desc="passes", unit="pass"):
        entry = {}
        for name in names[p % len(names) :] + names[: p % len(names)]:
            runs = [models.runners[name](s) for s in sequences]
            cpu, simulated = sum(r.cpu_s for r in runs), sum(r.simulated_s for r in runs)
            entry[name] = {
                "cpu_s_per_rollout": cpu / len(runs),
                "cpu_s_per_simulated_s": cpu / simulated,
                "simulated_s_per_rollout": simulated / len(runs),
                "load": os.getloadavg()[0],
                "moved": [r.moved for r in runs],
                "max_drift_mm": [float(np.max(r.drift) * 1000) for r in runs],
                "failed": [r.failed for r in runs],
                "robot_end": [r.robot_end.tolist() for r in runs],
            }
        passes.append({name: entry[name] for name in names})
    return passes


def summarise(passes: list[dict]) -> dict:
    """Medians over the passes per model, the paired Drake / MuJoCo ratios, and how far each model's
    robot ends from the execution model's (max over joints and sequences, m or rad)."""
    names = list(passes[0])
    execution = next(n for n in names if n.startswith("drake_execution"))
    summary = {}
    for name in names:
        first = passes[0][name]
        gap = np.abs(np.array(first["robot_end"]) - np.array(passes[0][execution]["robot_end"]))
        summary[name] = {
            "cpu_s_per_rollout_median": float(np.median([p[name]["cpu_s_per_rollout"] for p in passes])),
            "cpu_s_per_simulated_s_median": float(
                np.median([p[name]["cpu_s_per_simulated_s"] for p in passes])
            ),
            "moved_per_sequence": first["moved"],
            "failed": int(sum(first["failed"])),
            "robot_end_gap_to_execution": float(np.max(gap)),
            "same_every_pass": all(p[name]["moved"] == first["moved"] for p in passes),
        }
        if name.startswith("drake"):
            summary[name]["times_mujoco_median"] = {
                other: float(
                    np.median(
                        [p[name]["cpu_s_per_simulated_s"] / p[other]["cpu_s_per_simulated_s"] for p in passes]
                    )
                )
                for other in names
                if other.startswith("mujoco")
            }
    return summary


def plot(summary: dict, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = list(summary)
    values = [summary[n]["cpu_s_per_simulated_s_median"] for n in names]
    fig, ax = plt.subplots(figsize=(7, 3.5))
    colours = ["tab:orange" if n.startswith("mujoco") else "tab:blue" for n in names]
    bars = ax.bar(range(len(names)), values, color=colours)
    for bar, value in zip(bars, values):
        ax.annotate(f"{value:.3g}", (bar.get_x() + bar.get_width() / 2, value), ha="center", va="bottom")
    ax.set_yscale("log")
    ax.set_ylim(top=2 * max(values))  # room for the labels
    ax.set_xticks(range(len(names)), [n.replace("_", " ") for n in names], rotation=20, ha="right")
    ax.set_ylabel("CPU s per simulated s")
    ax.set_title("MuJoCo vs Drake, same scene and sequences (median over passes)")
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=120)
    plt.close(fig)


def print_table(report: dict) -> None:
    summary, idle = report["summary"], report["idle"]
    head = ("CPU s/rollout", "CPU s/sim s", "idle drift mm", "robot vs exec")
    print(f"{'model':22} " + " ".join(f"{h:>13}" for h in head) + "  moved > 1 cm per sequence")
    for name, s in summary.items():
        failed = f", {s['failed']} failed" if s["failed"] else ""
        cells = (
            s["cpu_s_per_rollout_median"],
            s["cpu_s_per_simulated_s_median"],
            idle[name]["max_drift_mm"],
            s["robot_end_gap_to_execution"],
        )
        print(f"{name:22} " + " ".join(f"{c:13.4g}" for c in cells) + f"  {s['moved_per_sequence']}{failed}")
    for name, s in summary.items():
        if name.startswith("drake"):
            ratios = ", ".join(
                f"x{r:.1f} {other.replace('_', ' ')}" for other, r in s["times_mujoco_median"].items()
            )
            print(f"{name.replace('_', ' ')} per simulated s (paired median): {ratios}")
    loads = [p[n]["load"] for p in report["passes"] for n in p]
    before = report["machine"]["load_before"][0]
    print(f"load average (1 min) before {before:.2f}, during {min(loads):.2f}-{max(loads):.2f}")


OUTPUTS = ("mujoco_anchor.json", "mujoco_anchor.png", "mujoco_anchor.xml")
"""The files of --out."""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--out", default="benchmark-results", help="output directory")
    parser.add_argument("--rollouts", type=int, default=8, help="noisy 3 s sequences per pass")
    parser.add_argument("--repeats", type=int, default=3, help="passes")
    parser.add_argument(
        "--steps", type=float, nargs="+", default=[0.002, 0.005, 0.02], help="MuJoCo time steps, s"
    )
    args = parser.parse_args()
    if mujoco is None:
        print(MISSING, file=sys.stderr)
        raise SystemExit(2)
    out = check_folder(args.out, *OUTPUTS)
    out.mkdir(exist_ok=True)
    scene, config, sequences = throughput_sequences(args.rollouts)
    models = Models.build(config, tuple(args.steps))
    m = models.mujoco.model
    report = {
        "machine": {
            "platform": platform.platform(),
            "cpus": os.cpu_count(),
            "python": platform.python_version(),
            "drake": importlib.metadata.version("drake"),
            "mujoco": mujoco.__version__,
            "load_before": os.getloadavg(),
        },
        "scene": scene.name,
        "objects": len(scene.objects),
        "horizon_s": HORIZON,
        "rollouts": args.rollouts,
        "mujoco_model": {
            "bodies": m.nbody,
            "free_joints": int(np.sum(m.jnt_type == mujoco.mjtJoint.mjJNT_FREE)),
            "joints": m.njnt,
            "geoms": m.ngeom,
            "actuators": m.nu,
            "equalities": m.neq,
            "excluded_body_pairs": m.nexclude,
            "integrator": INTEGRATOR,
        },
        "idle": idle_check(models, HORIZON),
    }
    report["passes"] = measure(models, sequences, args.repeats)
    report["summary"] = summarise(report["passes"])
    report["machine"]["load_after"] = os.getloadavg()
    write_text_atomic(out / "mujoco_anchor.json", json.dumps(report, indent=2) + "\n")
    write_text_atomic(out / "mujoco_anchor.xml", models.mujoco.xml + "\n")
    plot(report["summary"], out / "mujoco_anchor.png")
    print_table(report)
    print(f"wrote {out / 'mujoco_anchor.json'}, {out / 'mujoco_anchor.png'} and {out / 'mujoco_anchor.xml'}")


if __name__ == "__main__":
    raise SystemExit(run_cli(lambda _argv: main() or 0))  # bad paths: one line, exit 2
