"""Benchmarks of the stochastic trajectory optimiser (STO).

    python benchmarks/sto.py [--out DIR] [--gen1 10] [--throughput-rollouts 16] [--throughput-repeats 2]
                             [--skip-comparison]

1. Rollout throughput: rollouts of a 3 s horizon per second on a 9-object Generalization II scene,
   on 1 and on 2 worker processes (the same noisy sequences), on the execution model and on its
   reduced approximation (``sto.reduced_model``: objects nothing comes near asleep) side by side,
   repeated, at the plant's time step and at 10 ms; and the real-time factor of one rollout at those
   steps. Which execution model, and the validation sequences it is checked on
   (``validation_sequences``): ``physics_models.py``.
2. HLP-initialised vs straight-line-initialised optimisation, side by side in one run, on the
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
from dataclasses import replace
from pathlib import Path

import numpy as np
from tqdm import tqdm

from hlp_drake.commands.parsing import run_cli
from hlp_drake.files.atomic import atomic_path, check_folder, write_text_atomic
from hlp_drake.scene.generators import generate_scene
from hlp_drake.scene.io import load_scene
from hlp_drake.systems.execution.run import plan_and_execute
from hlp_drake.systems.low_level.control_sequence import ControlSequence
from hlp_drake.systems.low_level.sto.first_rollout import initial_sequence
from hlp_drake.systems.low_level.sto.optimiser import sample_base_noise
from hlp_drake.systems.low_level.sto.pool import RolloutPool
from hlp_drake.systems.low_level.sto.rollout_world import RolloutWorld
from hlp_drake.systems.low_level.sto.spec import RolloutSpec
from hlp_drake.systems.planning.initialisers import initialiser_name
from hlp_drake.systems.scenario import Scenario

DEFAULT_SCENE = Path(__file__).resolve().parents[1] / "hlp_drake" / "scenes" / "default.yaml"
HORIZON = 3.0


def truncated(sequence: ControlSequence, horizon: float) -> ControlSequence:
    """The first ``horizon`` s of ``sequence`` (minus the settle time the rollout adds)."""
    trajectory = sequence.to_trajectory()
    times = np.linspace(0.0, horizon, 8)
    return ControlSequence(times, np.column_stack([trajectory.value(t) for t in times]).T)


def noisy(sequence: ControlSequence, config: Scenario, count: int, seed: int) -> list[ControlSequence]:
    rng = np.random.default_rng(seed)
    return [
        sequence.with_base_velocity(v)
        for v in sample_base_noise(rng, sequence, config.low_level.noise, count)
    ]


def planned(scene, planner: str, data: str = "") -> Scenario:
    """The default scenario on ``scene`` with the initialiser ``planner`` ("hlp"; "sto": the straight
    line) and the YAML settings ``data``."""
    return Scenario(scene=scene).updated(f"planner: {{initial: {initialiser_name(planner)}}}\n{data}")


def throughput_sequences(count: int) -> tuple:
    """The throughput scene (gen2 seed 0, 9 obstacles), a configuration without settling, and
    ``count`` noisy copies of the first ``HORIZON`` s of its straight-line initial sequence."""
    scene = generate_scene("gen2", 0, 9)
    config = planned(scene, "sto", "success: {settle_s: 0.0}")
    base = truncated(initial_sequence(config), HORIZON)
    return scene, config, noisy(base, config, count, seed=1)


def model_config(config: Scenario, step: float, reduced: bool) -> Scenario:
    """``config`` with the plant's time step ``step`` and the reduced model on or off."""
    return config.updated(
        f"plant: {{time_step: {step}}}\nplanner: {{low_level: {{reduced_model: {str(reduced).lower()}}}}}"
    )


def throughput(count: int, steps: tuple[float, ...], repeats: int) -> dict:
    """Rollouts per second on 1 and 2 workers (same sequences), full and reduced model, at each
    rollout time step, ``repeats`` times, each time on cold worlds (only the full one built) and then
    on warm ones; the CPU time per rollout on 1 worker (in this process: less sensitive to other
    load than the rate); and the real-time factor of one rollout at those steps and at the
    execution's."""
    scene, config, sequences = throughput_sequences(count)
    result = {
        "scene": scene.name,
        "objects": len(scene.objects),
        "horizon_s": HORIZON,
        "rollouts": count,
        "load_before": os.getloadavg(),
    }
    for repeat in range(repeats):
        for step in steps:
            for model in ("full", "reduced"):
                cfg = RolloutSpec.of(model_config(config, step, model == "reduced"))
                entry = result.setdefault(f"step_{step * 1000:g}ms", {}).setdefault(model, {})
                for workers in (1, 2):
                    with RolloutPool(workers) as pool:
                        pool.rollouts(cfg, sequences[:workers])  # build the full worlds first
                        for rerun in ("cold", "warm"):  # warm: every reduced world built by the cold pass
                            started, cpu = time.perf_counter(), time.process_time()
                            outcomes = pool.rollouts(cfg, sequences)
                            elapsed, cpu = time.perf_counter() - started, time.process_time() - cpu
                            runs = entry.setdefault(f"workers_{workers}", {}).setdefault(rerun, [])
                            runs.append(
                                {
                                    "rollouts_per_s": count / elapsed,
                                    "wall_s": elapsed,
                                    "cpu_s_per_rollout": cpu / count if workers == 1 else None,
                                    "load": os.getloadavg()[0],
                                    "asleep_mean": float(np.mean([len(o.asleep) for o in outcomes])),
                                    "switches": [o.switches for o in outcomes],
                                    "costs": [o.cost for o in outcomes],
                                }
                            )
                runs = [
                    run for w in (1, 2) for rerun in ("cold", "warm") for run in entry[f"workers_{w}"][rerun]
                ]
                entry["same_costs_everywhere"] = all(run["costs"] == runs[0]["costs"] for run in runs)
    for step in steps:
        world = RolloutWorld(RolloutSpec.of(model_config(config, step, False)))
        world.rollout(sequences[0])
        walls = [world.rollout(s).wall_s for s in sequences[:4]]
        result.setdefault("real_time_factor", {})[f"{step * 1000:g}ms"] = HORIZON / float(np.median(walls))
    return result


def validation_sequences(count: int, scenes: int) -> list[tuple]:
    """(scene, label, sequence, settle) triples for the model agreement (see the module's docstring;
    ``count`` noisy copies per planner on the default scene, ``scenes`` Generalization I and II
    scenes each); settle says whether the rollout settles after the sequence (the 3 s throughput
    sequences do not)."""
    default = load_scene(DEFAULT_SCENE)
    triples = []
    for planner in ("hlp", "sto"):
        initial = initial_sequence(planned(default, planner))
        for i, sequence in enumerate(noisy(initial, Scenario(), count, seed=2)):
            triples.append((default, f"default/{planner}/noisy{i}", sequence, True))
    scene, _, sequences = throughput_sequences(2 * count)
    triples += [(scene, f"throughput/noisy{i}", s, False) for i, s in enumerate(sequences)]
    for kind, seed in [(kind, seed) for seed in range(scenes) for kind in ("gen1", "gen2")]:
        scene = generate_scene(kind, seed, 9 if kind == "gen2" else None)
        for planner in ("hlp", "sto"):
            sequence = initial_sequence(planned(scene, planner))
            if sequence is None:
                print(f"{kind} seed {seed}, {planner}: no initial trajectory, left out")
                continue
            triples.append((scene, f"{kind}{seed}/{planner}", sequence, True))
            triples.append(
                (scene, f"{kind}{seed}/{planner}/noisy", noisy(sequence, Scenario(), 1, seed=3)[0], True)
            )
    return triples


def nudged(sequence: ControlSequence, offset: float = 1e-6) -> ControlSequence:
    """``sequence`` with the base's x shifted by ``offset`` m after the start (for the full model's own
    sensitivity: how far apart two rollouts get that no model difference separates)."""
    knots = sequence.knots.copy()
    knots[1:, 0] += offset
    return ControlSequence(sequence.times, knots)


def comparison(config: Scenario, seeds: int, out: Path) -> dict:
    scenes = [load_scene(DEFAULT_SCENE)] + [generate_scene("gen1", seed) for seed in range(seeds)]
    rows = []
    for scene in tqdm(scenes, desc="HLP vs straight line", unit="scene"):
        for planner in ("hlp", "sto"):
            # A fresh pool: neither planner reuses the rollout worlds the other one built on this
            # scene (the pool's start-up is not in optimise_s).
            scenario = replace(
                config, scene=scene, planner=replace(config.planner, initial=initialiser_name(planner))
            )
            with RolloutPool(config.low_level.workers) as pool:
                result = plan_and_execute(scenario, pool=pool)
                rows.append(
                    {
                        "scene": scene.name,
                        "planner": planner,
                        "success": result.success,
                        "failure_reason": result.failure_reason or "",
                        "iterations": result.iterations,
                        "rollouts": result.rollouts,
                        "init_s": result.timings["plan_s"] + result.timings["ik_s"],
                        "optimise_s": result.timings["optimise_s"],
                        "grasp_held": result.grasp_held,
                    }
                )
    with atomic_path(out / "sto_comparison.csv") as tmp, tmp.open("w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    summary = {}
    for planner in ("hlp", "sto"):
        mine = [r for r in rows if r["planner"] == planner]
        times = np.array([r["optimise_s"] for r in mine])
        summary[planner] = {
            "scenes": len(mine),
            "success": int(sum(r["success"] for r in mine)),
            "optimise_s_median": float(np.median(times)),
            "optimise_s_mean": float(np.mean(times)),
            "rollouts_mean": float(np.mean([r["rollouts"] for r in mine])),
        }
    summary["ratio_hlp_to_sto_mean_optimise_s"] = (
        summary["hlp"]["optimise_s_mean"] / summary["sto"]["optimise_s_mean"]
    )
    summary["ratio_hlp_to_sto_median_optimise_s"] = (
        summary["hlp"]["optimise_s_median"] / summary["sto"]["optimise_s_median"]
    )
    plot_comparison(rows, out / "sto_comparison.png")
    return summary


def plot_comparison(rows: list[dict], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    x = np.arange(len(scenes))
    fig, ax = plt.subplots(figsize=(max(6, 0.7 * len(scenes) + 2), 4))
    for offset, planner, colour, label in (
        (-0.2, "hlp", "tab:green", "HLP-initialised"),
        (0.2, "sto", "tab:gray", "straight-line-initialised"),
    ):
        mine = {r["scene"]: r for r in rows if r["planner"] == planner}
        heights = [mine[s]["optimise_s"] for s in scenes]
        bars = ax.bar(x + offset, heights, 0.4, color=colour, label=label)
        for bar, s in zip(bars, scenes):
            if not mine[s]["success"]:
                ax.annotate(
                    "x",
                    (bar.get_x() + bar.get_width() / 2, bar.get_height()),
                    ha="center",
                    va="bottom",
                    color="red",
                )
    ax.set_xticks(x, scenes, rotation=45, ha="right")
    ax.set_ylabel("optimisation time (s)")
    ax.set_title("STO optimisation time per scene (red x: failed)")
    ax.legend()
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=120)
    plt.close(fig)


def print_throughput(t: dict, steps: tuple[float, ...]) -> None:
    print(
        f"throughput ({t['objects']} objects, {HORIZON:g} s horizon, {t['rollouts']} rollouts; "
        f"load before {t['load_before'][0]:.2f}), rollouts/s per repeat:"
    )
    for step in steps:
        for model in ("full", "reduced"):
            entry = t[f"step_{step * 1000:g}ms"][model]
            for w in (1, 2):
                cells = "; ".join(
                    f"{rerun} "
                    + ", ".join(
                        f"{run['rollouts_per_s']:.2f} (load {run['load']:.1f})"
                        for run in entry[f"workers_{w}"][rerun]
                    )
                    for rerun in ("cold", "warm")
                )
                print(f"  {step * 1000:g} ms, {model} model, {w} worker{'s' if w > 1 else ''}: {cells}")
            cpu = [
                run["cpu_s_per_rollout"] for rerun in ("cold", "warm") for run in entry["workers_1"][rerun]
            ]
            print(
                f"  {step * 1000:g} ms, {model} model: CPU time per rollout on 1 worker "
                + ", ".join(f"{c:.3f}" for c in cpu)
                + " s"
            )
            print(
                f"  {step * 1000:g} ms, {model} model: asleep at the end "
                f"{entry['workers_1']['cold'][0]['asleep_mean']:.1f} objects on average; same costs on 1 and 2 "
                f"workers, cold and warm: {entry['same_costs_everywhere']}"
            )
    print(
        "real-time factor of one rollout (full model): "
        + ", ".join(f"{rtf:.1f} at {k}" for k, rtf in t["real_time_factor"].items())
    )


OUTPUTS = ("sto_benchmark.json", "sto_comparison.csv", "sto_comparison.png")
"""The files of --out."""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--out", default="benchmark-results", help="output directory")
    parser.add_argument("--gen1", type=int, default=10, help="Generalization I scenes (seeds 0..N-1)")
    parser.add_argument("--throughput-rollouts", type=int, default=16)
    parser.add_argument(
        "--throughput-repeats", type=int, default=2, help="throughput measurements per setting"
    )
    parser.add_argument("--skip-comparison", action="store_true")
    args = parser.parse_args()
    out = check_folder(args.out, *OUTPUTS)
    out.mkdir(exist_ok=True)
    report = {
        "machine": {
            "platform": platform.platform(),
            "cpus": os.cpu_count(),
            "python": platform.python_version(),
        }
    }
    steps = (0.005, Scenario().plant.time_step)
    report["throughput"] = throughput(args.throughput_rollouts, steps, args.throughput_repeats)
    print_throughput(report["throughput"], steps)
    if not args.skip_comparison:
        report["comparison"] = c = comparison(Scenario(), args.gen1, out)
        for planner in ("hlp", "sto"):
            s = c[planner]
            print(
                f"{planner}: success {s['success']}/{s['scenes']}, optimise median {s['optimise_s_median']:.2f} s, "
                f"mean {s['optimise_s_mean']:.2f} s, rollouts mean {s['rollouts_mean']:.1f}"
            )
        print(
            f"HLP / straight line optimisation time: mean {c['ratio_hlp_to_sto_mean_optimise_s']:.2f}, "
            f"median {c['ratio_hlp_to_sto_median_optimise_s']:.2f}"
        )
    write_text_atomic(out / "sto_benchmark.json", json.dumps(report, indent=2) + "\n")
    print(f"wrote {out / 'sto_benchmark.json'}")


if __name__ == "__main__":
    raise SystemExit(run_cli(lambda _argv: main() or 0))  # bad paths: one line, exit 2
