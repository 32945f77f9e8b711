"""Benchmarks of the stochastic trajectory optimiser (STO).

    python benchmarks/sto.py [--out DIR] [--gen1 10] [--throughput-rollouts 16] [--skip-comparison]

1. Rollout throughput: rollouts of a 3 s horizon per second on a 9-object Generalization II scene,
   on 1 and on 2 worker processes (the same noisy sequences), and the real-time factor of one
   rollout at the rollout time step and at the execution time step.
2. The coarse rollout model against the full one: the same noisy sequences rolled out at the
   rollout time step and at the execution time step; how often their success verdicts agree.
3. HLP-initialised vs straight-line-initialised optimisation, side by side in one run, on the
   bundled default scene and the Generalization I scenes of seeds 0..N-1: success (after execution)
   and optimisation time per scene, with medians, means and the ratio.

Writes ``DIR/sto_benchmark.json``, ``DIR/sto_comparison.csv`` and ``DIR/sto_comparison.png``.
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import platform
import time
from pathlib import Path

import numpy as np
from tqdm import tqdm

from hlp_drake.scene.generators import generate_scene
from hlp_drake.scene.io import load_scene
from hlp_drake.systems.control_sequence import ControlSequence
from hlp_drake.systems.execution import plan_and_execute
from hlp_drake.systems.planning import make_planning_diagram
from hlp_drake.systems.rollout import RolloutWorld
from hlp_drake.systems.rollout_pool import RolloutPool
from hlp_drake.systems.sto import sample_base_noise
from hlp_drake.systems.world_config import WorldConfig

DEFAULT_SCENE = Path(__file__).resolve().parents[1] / "hlp_drake" / "scenes" / "default.yaml"
HORIZON = 3.0


def initial_sequence(scene, planner: str, config: WorldConfig) -> ControlSequence:
    diagram = make_planning_diagram(scene, planner=planner, config=config)
    context = diagram.CreateDefaultContext()
    diagram.GetInputPort("scene").FixValue(context, scene)
    return ControlSequence.from_trajectory(diagram.GetOutputPort("trajectory").Eval(context), config.sto.step_duration)


def truncated(sequence: ControlSequence, horizon: float) -> ControlSequence:
    """The first ``horizon`` s of ``sequence`` (minus the settle time the rollout adds)."""
    trajectory = sequence.to_trajectory()
    times = np.linspace(0.0, horizon, 8)
    return ControlSequence(times, np.column_stack([trajectory.value(t) for t in times]).T)


def noisy(sequence: ControlSequence, config: WorldConfig, count: int, seed: int) -> list[ControlSequence]:
    rng = np.random.default_rng(seed)
    return [sequence.with_base_velocity(v) for v in sample_base_noise(rng, sequence, config.sto.noise, count)]


def throughput(count: int, steps: tuple[float, ...]) -> dict:
    """Rollouts per second on 1 and 2 workers (same sequences) at each rollout time step, and the
    real-time factor of one rollout at those steps and at the execution's."""
    scene = generate_scene("gen2", 0, 9)
    config = WorldConfig()
    config.sto.settle_s = 0.0
    base = truncated(initial_sequence(scene, "sto", config), HORIZON)
    sequences = noisy(base, config, count, seed=1)
    result = {"scene": scene.name, "objects": len(scene.objects), "horizon_s": HORIZON, "rollouts": count}
    for step in steps:
        config.sto.rollout_time_step = step
        entry = result[f"step_{step * 1000:g}ms"] = {}
        for workers in (1, 2):
            with RolloutPool(workers) as pool:
                pool.rollouts(scene, config, sequences[:workers])  # build the worlds first
                started = time.perf_counter()
                outcomes = pool.rollouts(scene, config, sequences)
                elapsed = time.perf_counter() - started
            entry[f"workers_{workers}"] = {"rollouts_per_s": count / elapsed, "wall_s": elapsed,
                                           "costs": [o.cost for o in outcomes]}
        entry["same_costs_1_vs_2_workers"] = entry["workers_1"]["costs"] == entry["workers_2"]["costs"]
    for step in (*steps, WorldConfig().plant.time_step):
        timed = WorldConfig()
        timed.sto.settle_s = 0.0
        timed.sto.rollout_time_step = step
        world = RolloutWorld(scene, timed)
        world.rollout(sequences[0])
        walls = [world.rollout(s).wall_s for s in sequences[:4]]
        result.setdefault("real_time_factor", {})[f"{step * 1000:g}ms"] = HORIZON / float(np.median(walls))
    return result


def model_agreement(count: int, steps: tuple[float, ...]) -> dict:
    """Success verdicts of rollouts at each rollout time step vs the execution's, on the same noisy
    sequences around both planners' initial trajectories of the default scene."""
    scene = load_scene(DEFAULT_SCENE)
    full_step = WorldConfig().plant.time_step
    verdicts: dict[float, list[bool]] = {}
    for planner in ("hlp", "sto"):
        sequences = noisy(initial_sequence(scene, planner, WorldConfig()), WorldConfig(), count, seed=2)
        for step in (*steps, full_step):
            cfg = WorldConfig()
            cfg.sto.rollout_time_step = step
            world = RolloutWorld(scene, cfg)
            verdicts.setdefault(step, []).extend(world.rollout(s).success for s in sequences)
    full = verdicts[full_step]
    return {"scene": scene.name, "sequences": len(full), "successes_full_model": int(np.sum(full)),
            **{f"step_{step * 1000:g}ms": {"agreement": float(np.mean([a == b for a, b in zip(verdicts[step], full)])),
                                           "successes": int(np.sum(verdicts[step]))} for step in steps}}


def comparison(config: WorldConfig, seeds: int, out: Path) -> dict:
    scenes = [load_scene(DEFAULT_SCENE)] + [generate_scene("gen1", seed) for seed in range(seeds)]
    rows = []
    with RolloutPool(config.sto.workers) as pool:
        for scene in tqdm(scenes, desc="HLP vs straight line", unit="scene"):
            for planner in ("hlp", "sto"):
                result = plan_and_execute(scene, planner=planner, config=config, pool=pool)
                rows.append({"scene": scene.name, "planner": planner, "success": result.success,
                             "failure_reason": result.failure_reason or "", "iterations": result.iterations,
                             "rollouts": result.rollouts, "init_s": result.timings["plan_s"] + result.timings["ik_s"],
                             "optimise_s": result.timings["optimise_s"], "grasp_held": result.grasp_held})
    with (out / "sto_comparison.csv").open("w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    summary = {}
    for planner in ("hlp", "sto"):
        mine = [r for r in rows if r["planner"] == planner]
        times = np.array([r["optimise_s"] for r in mine])
        summary[planner] = {"scenes": len(mine), "success": int(sum(r["success"] for r in mine)),
                            "optimise_s_median": float(np.median(times)), "optimise_s_mean": float(np.mean(times)),
                            "rollouts_mean": float(np.mean([r["rollouts"] for r in mine]))}
    summary["ratio_hlp_to_sto_mean_optimise_s"] = summary["hlp"]["optimise_s_mean"] / summary["sto"]["optimise_s_mean"]
    summary["ratio_hlp_to_sto_median_optimise_s"] = summary["hlp"]["optimise_s_median"] / summary["sto"]["optimise_s_median"]
    plot_comparison(rows, out / "sto_comparison.png")
    return summary


def plot_comparison(rows: list[dict], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    x = np.arange(len(scenes))
    fig, ax = plt.subplots(figsize=(max(6, 0.7 * len(scenes) + 2), 4))
    for offset, planner, colour, label in ((-0.2, "hlp", "tab:green", "HLP-initialised"),
                                           (0.2, "sto", "tab:gray", "straight-line-initialised")):
        mine = {r["scene"]: r for r in rows if r["planner"] == planner}
        heights = [mine[s]["optimise_s"] for s in scenes]
        bars = ax.bar(x + offset, heights, 0.4, color=colour, label=label)
        for bar, s in zip(bars, scenes):
            if not mine[s]["success"]:
                ax.annotate("x", (bar.get_x() + bar.get_width() / 2, bar.get_height()), ha="center", va="bottom", color="red")
    ax.set_xticks(x, scenes, rotation=45, ha="right")
    ax.set_ylabel("optimisation time (s)")
    ax.set_title("STO optimisation time per scene (red x: failed)")
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--out", default="benchmark-results", help="output directory")
    parser.add_argument("--gen1", type=int, default=10, help="Generalization I scenes (seeds 0..N-1)")
    parser.add_argument("--throughput-rollouts", type=int, default=16)
    parser.add_argument("--agreement-sequences", type=int, default=8, help="noisy sequences per planner")
    parser.add_argument("--skip-comparison", action="store_true")
    args = parser.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    report = {"machine": {"platform": platform.platform(), "cpus": os.cpu_count(), "python": platform.python_version()}}
    steps = (WorldConfig().sto.rollout_time_step, 0.01)
    report["throughput"] = t = throughput(args.throughput_rollouts, steps)
    for step in steps:
        entry = t[f"step_{step * 1000:g}ms"]
        print(f"throughput at {step * 1000:g} ms ({t['objects']} objects, {HORIZON:g} s horizon): "
              f"{entry['workers_1']['rollouts_per_s']:.2f} rollouts/s on 1 worker, "
              f"{entry['workers_2']['rollouts_per_s']:.2f} on 2; same costs: {entry['same_costs_1_vs_2_workers']}")
    print("real-time factor of one rollout: " + ", ".join(f"{rtf:.1f} at {k}" for k, rtf in t["real_time_factor"].items()))
    report["model_agreement"] = a = model_agreement(args.agreement_sequences, steps)
    for step in steps:
        entry = a[f"step_{step * 1000:g}ms"]
        print(f"rollout model at {step * 1000:g} ms vs execution step: {entry['agreement']:.0%} of {a['sequences']} "
              f"verdicts agree ({entry['successes']} vs {a['successes_full_model']} successes)")
    if not args.skip_comparison:
        report["comparison"] = c = comparison(WorldConfig(), args.gen1, out)
        for planner in ("hlp", "sto"):
            s = c[planner]
            print(f"{planner}: success {s['success']}/{s['scenes']}, optimise median {s['optimise_s_median']:.2f} s, "
                  f"mean {s['optimise_s_mean']:.2f} s, rollouts mean {s['rollouts_mean']:.1f}")
        print(f"HLP / straight line optimisation time: mean {c['ratio_hlp_to_sto_mean_optimise_s']:.2f}, "
              f"median {c['ratio_hlp_to_sto_median_optimise_s']:.2f}")
    (out / "sto_benchmark.json").write_text(json.dumps(report, indent=2) + "\n")
    print(f"wrote {out / 'sto_benchmark.json'}")


if __name__ == "__main__":
    main()
