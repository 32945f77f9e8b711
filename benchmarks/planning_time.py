"""Planning time of the human-like planner with its bundled models, beside another release's.

    python benchmarks/planning_time.py [--dataset PATH] [--scenes 50] [--rounds 3]
        [--baseline CHECKOUT] [--stages] [--json OUT] [--png OUT]

Scene groups: the VR structured scenes of 5 held-out subjects (one 19/5 split), every unstructured
VR scene, seeded Generalization II scenes with 6, 12, 25 and 50 objects (sizes the generator
cannot place are reported as such; their row count grows too), and two-row scenes with 6, 12, 25
and 50 boxes (the object count alone). Every round plans every scene once in a fresh process of
this checkout, then (with --baseline, a checkout with its own .venv, e.g. a worktree of the
previous release) once in one of the baseline; the order alternates between rounds, so both see
the same machine load. A scene's time is its fastest over the rounds. Prints the median, p95 and
p99 per group and planner, and the ratio of the medians, on the wall clock and in CPU time (the
planning thread's: what other jobs on a shared machine disturb least); writes JSON and a PNG.
With --stages, also where this checkout's plan spends its CPU time: each scene planned once more
in this process with the planner's stages (``STAGES``) timed, their mean ms per plan per group.
"""

from __future__ import annotations

import argparse
import functools
import importlib
import json
import pickle
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from tqdm import tqdm

from hlp_drake.commands.parsing import run_cli
from hlp_drake.dataset import STRUCTURED, UNSTRUCTURED, Dataset
from hlp_drake.errors import HlpError
from hlp_drake.evaluation import subject_splits
from hlp_drake.files.atomic import check_writable, write_text_atomic
from hlp_drake.files.plotting import new_figure, save_png
from hlp_drake.scene.generators import generate_scene
from hlp_drake.scene.model import Scene, SceneObject, Table
from hlp_drake.segmentation import demonstration_records
from hlp_drake.taskspace import TaskSpace

DEFAULT = Path(__file__).resolve().parents[1].parent / "shared" / "data"
# Runs in each planner's own interpreter: plan every pickled scene once (after a warm-up), write
# each plan's times: the plan's own (wall clock) and the planning thread's CPU time.
WORKER = """
import json, pickle, sys, time
from hlp_drake.learners.bundled import default_models
from hlp_drake.planner import plan
groups = pickle.load(open(sys.argv[1], "rb"))
models = default_models()
for scenes in groups.values():
    for scene in scenes[:3]:
        plan(scene, models)
def timed(scene):
    cpu = time.thread_time()
    wall = plan(scene, models).planning_time_s
    return [wall, time.thread_time() - cpu]
json.dump({name: [timed(s) for s in scenes] for name, scenes in groups.items()}, open(sys.argv[2], "w"))
"""
CLOCKS = ("wall", "cpu")
STAGES = {  # label: (module, attribute); none runs inside another. set-up: the route graph and tables
    "validation": ("hlp_drake.planner.hlp", "scene_problems"),
    "task space": ("hlp_drake.planner.hlp", "TaskSpace"),
    "set-up": ("hlp_drake.planner.row_plan", "_Expander"),
    "row features": ("hlp_drake.features.row_choice", "RowChoiceScene.candidates"),
    "Cr": ("hlp_drake.learners.choice", "RowChoiceClassifier.predict_proba"),
    "Cr novelty": ("hlp_drake.learners.choice", "RowChoiceClassifier.novelty"),
    "Cd": ("hlp_drake.planner.row_plan", "_Expander.moves"),
    "arm Ra": ("hlp_drake.planner.row_plan", "arm_configurations"),
    "arm sweeps": ("hlp_drake.planner.row_plan", "expected_collisions"),
    "segments": ("hlp_drake.planner.row_plan", "plans_segment_collisions"),
}


def two_row_scene(objects: int, seed: int) -> Scene:
    """``objects`` boxes in two rows on a table wide enough for them (isolates the object count
    from the row count, which random layouts also grow)."""
    rng = np.random.default_rng(seed)
    per_row = [objects // 2, objects - objects // 2]
    width = max(1.0, 0.12 * max(per_row) + 0.2)
    obstacles = []
    for row, (count, x) in enumerate(zip(per_row, (0.35, 0.6)), start=1):
        slots = np.linspace(-width / 2 + 0.08, width / 2 - 0.08, count)
        for i, y in enumerate(slots):
            obstacles.append(
                SceneObject(
                    f"r{row}_{i}",
                    "box",
                    x,
                    float(y + rng.uniform(-0.01, 0.01)),
                    (0.05, float(rng.uniform(0.05, 0.08)), 0.12),
                )
            )
    return Scene(
        Table(1.0, width, 0.75),
        (0.1, 0.0),
        SceneObject("Target", "cylinder", 0.85, 0.0, (0.06, 0.06, 0.12)),
        tuple(obstacles),
        name=f"two-row-{objects}-{seed}",
    )


def scene_groups(dataset_path: str, count: int) -> tuple[dict[str, list[Scene]], dict[str, str]]:
    """The scenes of every group, and the groups the generator could not make (with the reason)."""
    dataset = Dataset(dataset_path, progress=False)
    _, test = subject_splits(dataset.subjects, n_train=19, splits=1, seed=0)[0]
    groups = {
        "vr_structured": [dataset.scene(r.key) for r in demonstration_records(dataset, test, (STRUCTURED,))],
        "vr_unstructured": [
            dataset.scene(r.key) for r in demonstration_records(dataset, None, (UNSTRUCTURED,))
        ],
    }
    failed = {}
    for objects in (6, 12, 25, 50):
        try:
            groups[f"gen2_{objects}"] = [generate_scene("gen2", seed, objects) for seed in range(count)]
        except HlpError as error:
            failed[f"gen2_{objects}"] = str(error)
    for objects in (6, 12, 25, 50):
        groups[f"two_rows_{objects}"] = [two_row_scene(objects, seed) for seed in range(count)]
    return {name: scenes for name, scenes in groups.items() if scenes}, failed


def time_rounds(groups: dict[str, list[Scene]], pythons: dict[str, str], rounds: int) -> dict[str, dict]:
    """Per planner and group, each scene's fastest planning time over ``rounds`` fresh processes,
    wall clock (``median_ms``, ...) and CPU (``cpu_median_ms``, ...)."""
    best: dict[str, dict[str, np.ndarray]] = {}
    with tempfile.TemporaryDirectory() as tmp:
        scenes = Path(tmp) / "scenes.pkl"
        scenes.write_bytes(pickle.dumps(groups))
        order = list(pythons)
        for r in tqdm(range(rounds), desc="rounds", unit="round"):
            for name in order if r % 2 == 0 else order[::-1]:
                out = Path(tmp) / f"{name}.json"
                subprocess.run([pythons[name], "-c", WORKER, str(scenes), str(out)], cwd=tmp, check=True)
                times = {g: np.array(t) for g, t in json.loads(out.read_text()).items()}
                best[name] = (
                    times if name not in best else {g: np.minimum(best[name][g], t) for g, t in times.items()}
                )
    return {name: {g: _stats(t) for g, t in per_group.items()} for name, per_group in best.items()}


def stage_times(groups: dict[str, list[Scene]]) -> dict[str, dict[str, float]]:
    """Per group, the mean CPU ms per plan of each of this checkout's ``STAGES`` and of the rest
    ("other"), each scene planned once (after a warm-up) with the stages wrapped in timers."""
    from hlp_drake.learners.bundled import default_models
    from hlp_drake.planner import plan

    spent: dict[str, float] = {}

    def timed(label: str, function):
        @functools.wraps(function)
        def wrapper(*args, **kwargs):
            started = time.thread_time()
            try:
                return function(*args, **kwargs)
            finally:
                spent[label] = spent.get(label, 0.0) + time.thread_time() - started

        return wrapper

    targets = []  # every owner looked up before any is wrapped (a class's methods, then the class)
    for label, (module, path) in STAGES.items():
        *parents, name = path.split(".")
        targets.append((label, functools.reduce(getattr, parents, importlib.import_module(module)), name))
    for label, owner, name in targets:
        setattr(owner, name, timed(label, getattr(owner, name)))
    models, result = default_models(), {}
    for group, scenes in groups.items():
        for scene in scenes[:3]:
            plan(scene, models)
        spent.clear()
        started = time.thread_time()
        for scene in scenes:
            plan(scene, models)
        total = time.thread_time() - started
        result[group] = {label: spent.get(label, 0.0) * 1e3 / len(scenes) for label in STAGES}
        result[group]["other"] = (total - sum(spent.values())) * 1e3 / len(scenes)
    return result


def _stats(times: np.ndarray) -> dict:
    """Median, p95 and p99 (ms) of (scenes, 2) wall and CPU times."""
    stats: dict = {"scenes": len(times)}
    for clock, t in zip(CLOCKS, np.asarray(times).reshape(-1, 2).T):
        prefix = "" if clock == "wall" else f"{clock}_"
        for name, q in (("median", 50), ("p95", 95), ("p99", 99)):
            stats[f"{prefix}{name}_ms"] = float(np.percentile(t, q) * 1e3)
    return stats


def plot(report: dict, path: str) -> None:
    figure, axes = new_figure(9.0, 4.2)
    groups = list(report["planners"]["this"])
    for k, name in enumerate(report["planners"]):
        medians = [report["planners"][name][g]["median_ms"] for g in groups]
        p99 = [report["planners"][name][g]["p99_ms"] - m for g, m in zip(groups, medians)]
        x = np.arange(len(groups)) + (k - 0.5) * 0.4
        axes.bar(
            x, medians, 0.4, yerr=[np.zeros(len(groups)), p99], capsize=2, label=f"{name} (median, to p99)"
        )
    axes.set_xticks(np.arange(len(groups)), groups, rotation=30, ha="right", fontsize=8)
    axes.set_ylabel("planning time per scene, ms")
    axes.grid(axis="y", alpha=0.3)
    axes.legend(fontsize=8)
    axes.set_title("Planning time (fastest of the rounds per scene)")
    save_png(figure, path)


def print_table(report: dict, planners: list[str], clock: str) -> None:
    """Median, p95, p99 per group and planner on ``clock`` ("wall" or "cpu"), and the medians' ratio."""
    prefix = "" if clock == "wall" else f"{clock}_"
    print(
        f"{clock + ' time':18s} {'rows':>5s}"
        + "".join(f" {n + ' median':>16s} {'p95':>7s} {'p99':>7s}" for n in planners)
        + ("   ratio" if len(planners) > 1 else "")
    )
    for g, rows in report["rows_mean"].items():
        line = f"{g:18s} {rows:5.1f}"
        for name in planners:
            t = report["planners"][name][g]
            line += (
                f" {t[prefix + 'median_ms']:13.2f} ms {t[prefix + 'p95_ms']:7.2f} {t[prefix + 'p99_ms']:7.2f}"
            )
        if len(planners) > 1:
            this, baseline = (report["planners"][n][g][prefix + "median_ms"] for n in ("this", "baseline"))
            line += f"   {this / baseline:.2f}"
        print(line)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--dataset", default=str(DEFAULT))
    parser.add_argument("--scenes", type=int, default=50, help="generated scenes per object count")
    parser.add_argument(
        "--rounds", type=int, default=3, help="plan every scene this often, keep its fastest time"
    )
    parser.add_argument("--baseline", type=Path, help="a checkout with its own .venv to time beside this one")
    parser.add_argument("--stages", action="store_true", help="also time this checkout's planner stages")
    parser.add_argument("--json")
    parser.add_argument("--png")
    args = parser.parse_args()
    check_writable(args.json, args.png)
    groups, failed = scene_groups(args.dataset, args.scenes)
    pythons = {"this": sys.executable}
    if args.baseline is not None:
        pythons["baseline"] = str(args.baseline.resolve() / ".venv" / "bin" / "python")
    report = {
        "machine": f"{platform.processor() or platform.machine()}, Python {platform.python_version()}",
        "rounds": args.rounds,
        "baseline": str(args.baseline) if args.baseline else None,
        "rows_mean": {
            g: float(np.mean([len(TaskSpace(s).rows) for s in scenes])) for g, scenes in groups.items()
        },
        "not_generated": failed,
        "planners": time_rounds(groups, pythons, args.rounds),
    }
    for clock in CLOCKS:
        print_table(report, list(pythons), clock)
    if args.stages:
        report["stages_ms"] = stage_times(groups)
        labels = [*STAGES, "other"]
        print("CPU ms per plan   " + " ".join(f"{label[:12]:>12s}" for label in labels))
        for group, stages in report["stages_ms"].items():
            print(f"{group:18s}" + " ".join(f"{stages[label]:12.2f}" for label in labels))
    for g, reason in failed.items():
        print(f"{g}: not generated ({reason})")
    if args.json:
        write_text_atomic(args.json, json.dumps(report, indent=2) + "\n")
    if args.png:
        plot(report, args.png)


if __name__ == "__main__":
    started = time.perf_counter()
    status = run_cli(lambda _argv: main() or 0)  # bad paths: one line, exit 2
    print(f"({time.perf_counter() - started:.0f} s)", file=sys.stderr)
    raise SystemExit(status)
