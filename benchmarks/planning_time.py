"""Planning time of the human-like planner with the bundled models, and per-scene feature time.

    python benchmarks/planning_time.py [--dataset PATH] [--scenes 50] [--rounds 1] [--json OUT]

Scenes: the VR scenes of 5 held-out subjects (the ~450 test scenes of one 19/5 split), seeded
Generalization II scenes with 6, 12, 25 and 50 objects (sizes the generator cannot place are
reported as such; their row count grows too), and two-row scenes with 6, 12, 25 and 50 boxes (the
object count alone). Prints the median and 95th percentile per group, then a table of them.
With ``--rounds R`` every scene is planned R times (all scenes of a group once per round) and its
fastest time counts, which steadies the figures on a busy machine.
"""

from __future__ import annotations

import argparse
import json
import platform
import time
import timeit
from pathlib import Path

import numpy as np

from hlp_drake.dataset import Dataset
from hlp_drake.errors import HlpError
from hlp_drake.evaluation import subject_splits
from hlp_drake.features import gap_features, object_features, segment_feature_matrix
from hlp_drake.learners.bundled import default_models
from hlp_drake.planner import plan
from hlp_drake.scene.generators import generate_scene
from hlp_drake.scene.model import Scene, SceneObject, Table
from hlp_drake.segmentation import demonstration_records
from hlp_drake.taskspace import TaskSpace

DEFAULT = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "hlp-vr-dataset.tar.xz"


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
            obstacles.append(SceneObject(f"r{row}_{i}", "box", x, float(y + rng.uniform(-0.01, 0.01)),
                                         (0.05, float(rng.uniform(0.05, 0.08)), 0.12)))
    return Scene(Table(1.0, width, 0.75), (0.1, 0.0), SceneObject("Target", "cylinder", 0.85, 0.0, (0.06, 0.06, 0.12)),
                 tuple(obstacles), name=f"two-row-{objects}-{seed}")


def times(scenes, models, rounds: int = 1) -> dict[str, float]:
    for scene in scenes[:3]:
        plan(scene, models)  # warm up
    t = np.min([[plan(scene, models).planning_time_s for scene in scenes] for _ in range(rounds)], axis=0)
    return {"scenes": len(scenes), "median_ms": float(np.median(t) * 1e3), "p95_ms": float(np.percentile(t, 95) * 1e3)}


def table(report: dict) -> str:
    """The timed groups as a text table."""
    lines = [f"{'group':16s} {'scenes':>6s} {'rows':>5s} {'median ms':>10s} {'p95 ms':>8s}"]
    for name, value in report.items():
        if isinstance(value, dict) and "median_ms" in value:
            rows = f"{value['rows_mean']:.1f}" if "rows_mean" in value else "2.0" if name.startswith("two_rows") else ""
            lines.append(f"{name:16s} {value['scenes']:6d} {rows:>5s} {value['median_ms']:10.2f} {value['p95_ms']:8.2f}")
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--dataset", default=str(DEFAULT))
    parser.add_argument("--scenes", type=int, default=50, help="generated scenes per object count")
    parser.add_argument("--rounds", type=int, default=1, help="plan every scene this often, keep its fastest time")
    parser.add_argument("--json")
    args = parser.parse_args()
    models = default_models()
    report: dict = {"machine": f"{platform.processor() or platform.machine()}, {platform.python_version()}"}
    dataset = Dataset(args.dataset, progress=False)
    _, test = subject_splits(dataset.subjects, n_train=19, splits=1, seed=0)[0]
    vr = [dataset.scene(r.key) for r in demonstration_records(dataset, test)]
    report["vr_test_scenes"] = times(vr, models, args.rounds)
    space = TaskSpace(vr[0])
    feature_time = timeit.timeit(lambda: (gap_features(TaskSpace(vr[0])), object_features(TaskSpace(vr[0]))), number=300)
    segment_time = timeit.timeit(lambda: segment_feature_matrix(space, space.nodes(1), space.nodes(2), mode="fixed"),
                                 number=300)
    report["features_per_scene_ms"] = {"task_space_gap_object": feature_time / 300 * 1e3,
                                       "segment_grid_7x7": segment_time / 300 * 1e3}
    for objects in (6, 12, 25, 50):
        try:
            scenes = [generate_scene("gen2", seed, objects) for seed in range(args.scenes)]
        except HlpError as error:
            report[f"gen2_{objects}"] = {"error": str(error)}
            continue
        report[f"gen2_{objects}"] = times(scenes, models, args.rounds) | {
            "rows_mean": float(np.mean([len(TaskSpace(s).rows) for s in scenes]))}
    for objects in (6, 12, 25, 50):
        report[f"two_rows_{objects}"] = times([two_row_scene(objects, seed) for seed in range(args.scenes)], models,
                                              args.rounds)
    for name, value in report.items():
        print(f"{name}: {value}")
    print(table(report))
    if args.json:
        Path(args.json).write_text(json.dumps(report, indent=2) + "\n")


if __name__ == "__main__":
    started = time.perf_counter()
    main()
    print(f"({time.perf_counter() - started:.0f} s)")
