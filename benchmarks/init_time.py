"""Initialisation time (high-level plan + keypoint IK) per object count, the issue's flatness figure.

    python benchmarks/init_time.py [--scenes 30] [--seed S] [--objects 5 7 9] [--planner hlp]
        [--repeat 3] [--against-iterations 500] [--json OUT] [--png OUT]

Plans every seeded Generalization II scene (and as many Generalization I scenes) in this process
and solves its keypoints' IK through ``make_planning_diagram`` (no optimiser), timing each scene in
CPU seconds of this thread (``time.thread_time``: the figure does not depend on the machine's load)
and in wall seconds beside it, each the least of ``--repeat`` solves in fresh contexts (the
plan and IK are deterministic, so the least is the one least slowed by other processes; the
keyframes of the repeats must agree). Prints the median, mean and p95 per object count, the same
of the plan alone (the ``robot_plan`` port: high-level plan and transfer, before the IK), and the
max/min ratio of the medians and of the means across the counts (the issue's target: <= 1.2 from
5 to 9 objects). With ``--against-iterations N`` every scene is solved a second time, right after, with
``ik.max_iterations = N`` (e.g. the earlier default, 500): both times per scene and whether the
keyframes agree (every keypoint's success alike, positions within 1e-4).
"""

from __future__ import annotations

import argparse
import json
import platform
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
from tqdm import tqdm

from hlp_drake.commands.parsing import run_cli
from hlp_drake.files.atomic import check_writable, write_text_atomic
from hlp_drake.files.plotting import new_figure, save_png
from hlp_drake.learners.bundled import default_models
from hlp_drake.scene.generators import generate_scene
from hlp_drake.scene.model import Scene
from hlp_drake.systems.planning.diagram import make_planning_diagram
from hlp_drake.systems.planning.initialisers import initialiser_name
from hlp_drake.systems.planning.keyframes import Keyframes
from hlp_drake.systems.scenario import Scenario, load_scenario
from hlp_drake.systems.world.scene_source import SCENE_PORT

SAME_POSITIONS = 1e-4
"""Keyframes whose positions differ by at most this (rad or m) count as the same."""


def timed_init(scenario: Scenario, repeat: int = 1) -> tuple[float, float, float, Keyframes]:
    """(CPU s, wall s, CPU s of the plan alone, keyframes) of planning ``scenario``'s scene (the
    ``robot_plan`` port: high-level plan and transfer) and solving its IK: the least times of
    ``repeat`` solves, each in a fresh context of one planning diagram."""
    diagram = make_planning_diagram(scenario, models=default_models())
    cpus, walls, plans, solved = [], [], [], []
    for _ in range(repeat):
        context = diagram.CreateDefaultContext()
        diagram.GetInputPort(SCENE_PORT).FixValue(context, scenario.scene)
        cpu, wall = time.thread_time(), time.perf_counter()
        diagram.GetOutputPort("robot_plan").Eval(context)
        plans.append(time.thread_time() - cpu)
        keyframes = diagram.GetOutputPort("keyframes").Eval(context)
        cpus.append(time.thread_time() - cpu)
        walls.append(time.perf_counter() - wall)
        solved.append(keyframes)
    if not all(same_keyframes(solved[0], other, 0.0) for other in solved[1:]):
        raise RuntimeError(f"{scenario.scene.name}: the repeated solves gave different keyframes")
    return min(cpus), min(walls), min(plans), solved[0]


def same_keyframes(a: Keyframes, b: Keyframes, tolerance: float = SAME_POSITIONS) -> bool:
    return (
        a.success == b.success
        and a.positions.shape == b.positions.shape
        and bool(np.all(np.abs(a.positions - b.positions) <= tolerance))
    )


def stats(values: list[float]) -> dict[str, float]:
    return {
        "median": float(np.median(values)),
        "mean": float(np.mean(values)),
        "p95": float(np.percentile(values, 95)),
        "max": float(np.max(values)),
    }


def spread(groups: dict[str, dict[str, dict[str, float]]], key: str, statistic: str) -> float:
    """max/min of ``statistic`` of ``key`` over the Generalization II groups."""
    values = [g[key][statistic] for label, g in groups.items() if label.startswith("gen2")]
    return max(values) / min(values)


def _parser() -> argparse.ArgumentParser:
    """The command line of ``python benchmarks/init_time.py``."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", type=int, default=30, help="scenes per group")
    parser.add_argument("--seed", type=int, default=0, help="scene i has seed S + i")
    parser.add_argument("--objects", type=int, nargs="+", default=[5, 7, 9], help="gen2 object counts")
    parser.add_argument(
        "--planner", choices=("hlp", "line", "sto"), default="hlp", help="the initialiser (sto: line)"
    )
    parser.add_argument("--repeat", type=int, default=3, help="solves per scene; its least time counts")
    parser.add_argument("--against-iterations", type=int, help="also solve with this ik.max_iterations")
    parser.add_argument("--json", type=Path, help="write the figures and rows here")
    parser.add_argument("--png", type=Path, help="box plot of the CPU times per group")
    return parser


def time_groups(settings: Scenario, groups: dict[str, list[Scene]], args: argparse.Namespace) -> list[dict]:
    """A row per scene of ``groups``: its times, keypoints and IK verdict (and, with
    ``--against-iterations``, the second solve's times and whether its keyframes agree)."""
    rows = []
    progress = tqdm(total=sum(map(len, groups.values())), desc="plan + IK", unit="scene")
    for label, scenes in groups.items():
        for scene in scenes:
            scenario = replace(settings, scene=scene)
            cpu, wall, plan, keyframes = timed_init(scenario, args.repeat)
            row = {"group": label, "scene": scene.name, "cpu_s": cpu, "wall_s": wall, "plan_cpu_s": plan}
            row["keypoints"] = len(keyframes.keypoints)
            row["ik_ok"] = keyframes.ok
            if args.against_iterations is not None:
                other = replace(scenario, ik=replace(scenario.ik, max_iterations=args.against_iterations))
                other_cpu, other_wall, _, other_keyframes = timed_init(other, args.repeat)
                row |= {
                    "against_cpu_s": other_cpu,
                    "against_wall_s": other_wall,
                    "same_keyframes": same_keyframes(keyframes, other_keyframes),
                }
            rows.append(row)
            progress.update()
    progress.close()
    return rows


def summarise(groups: dict[str, list[Scene]], rows: list[dict], against: int | None) -> dict[str, dict]:
    """The statistics of every group's rows (with ``against``: of the second solve's too)."""
    summary: dict[str, dict] = {}
    for label in groups:
        group = [r for r in rows if r["group"] == label]
        summary[label] = {
            "scenes": len(group),
            "cpu_s": stats([r["cpu_s"] for r in group]),
            "plan_cpu_s": stats([r["plan_cpu_s"] for r in group]),
            "wall_s": stats([r["wall_s"] for r in group]),
            "keypoints": stats([r["keypoints"] for r in group]),
            "ik_ok": sum(r["ik_ok"] for r in group),
        }
        if against is not None:
            summary[label]["against_cpu_s"] = stats([r["against_cpu_s"] for r in group])
            summary[label]["same_keyframes"] = sum(r["same_keyframes"] for r in group)
    return summary


def print_summary(summary: dict[str, dict], figures: dict[str, float], args: argparse.Namespace) -> None:
    print(
        f"{args.planner} init (plan + IK) per scene, ms: median / mean / p95 CPU (wall median), "
        "of it the plan median / mean"
    )
    for label, s in summary.items():
        cpu, wall = s["cpu_s"], s["wall_s"]
        line = (
            f"  {label:16s} {cpu['median'] * 1e3:6.0f} / {cpu['mean'] * 1e3:6.0f} / {cpu['p95'] * 1e3:6.0f}"
            f"  ({wall['median'] * 1e3:.0f}), of it the plan {s['plan_cpu_s']['median'] * 1e3:.0f} / "
            f"{s['plan_cpu_s']['mean'] * 1e3:.0f}  keypoints {s['keypoints']['median']:.0f}, IK ok {s['ik_ok']}"
        )
        if args.against_iterations is not None:
            against = s["against_cpu_s"]
            line += (
                f"; max_iterations {args.against_iterations}: {against['median'] * 1e3:.0f} / "
                f"{against['mean'] * 1e3:.0f} / {against['p95'] * 1e3:.0f}, "
                f"same keyframes {s['same_keyframes']}/{s['scenes']}"
            )
        print(line)
    for name, value in figures.items():
        print(f"  {name}: {value:.2f}")


def plot(groups: dict[str, list[Scene]], rows: list[dict], title: str, path: Path) -> None:
    """A box plot of the CPU times per group."""
    figure, axes = new_figure(7.0, 4.0)
    axes.boxplot([[r["cpu_s"] * 1e3 for r in rows if r["group"] == g] for g in groups])
    axes.set_xticks(range(1, len(groups) + 1), list(groups))
    axes.set_ylabel("plan + IK, CPU ms")
    axes.set_yscale("log")
    axes.set_title(title)
    save_png(figure, path)


def main() -> None:
    args = _parser().parse_args()
    check_writable(args.json, args.png)
    settings = load_scenario()
    settings = replace(settings, planner=replace(settings.planner, initial=initialiser_name(args.planner)))
    groups: dict[str, list[Scene]] = {
        "gen1": [generate_scene("gen1", args.seed + i) for i in range(args.scenes)],
        **{
            f"gen2, {n} objects": [generate_scene("gen2", args.seed + i, n) for i in range(args.scenes)]
            for n in args.objects
        },
    }
    default_models()  # loaded before the first timed scene
    rows = time_groups(settings, groups, args)
    summary = summarise(groups, rows, args.against_iterations)
    figures = {
        f"gen2 max/min of the {statistic} CPU s": spread(summary, "cpu_s", statistic)
        for statistic in ("median", "mean")
    } | {
        f"gen2 max/min of the {statistic} plan CPU s": spread(summary, "plan_cpu_s", statistic)
        for statistic in ("median", "mean")
    }
    print_summary(summary, figures, args)
    if args.json is not None:
        record = {
            "command": " ".join(["python benchmarks/init_time.py", *sys.argv[1:]]),
            "machine": platform.platform(),
            "ik_max_iterations": settings.ik.max_iterations,
            "repeat": args.repeat,
            "summary": summary,
            "figures": figures,
            "rows": rows,
        }
        write_text_atomic(args.json, json.dumps(record, indent=1))
    if args.png is not None:
        title = f"{args.planner} initialisation per scene (ik.max_iterations {settings.ik.max_iterations})"
        plot(groups, rows, title, args.png)


if __name__ == "__main__":
    raise SystemExit(run_cli(lambda _argv: main() or 0))  # bad paths: one line, exit 2
