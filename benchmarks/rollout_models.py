"""Which rollout model: throughput per core and agreement with the execution model, side by side.

    python benchmarks/rollout_models.py [--out DIR] [--rollouts 8] [--repeats 3] [--sequences 8]
        [--scenes 2] [--models full_5ms default ...] [--agreement-models ...] [--nudge 1e-6]
        [--skip-agreement]

1. Throughput: CPU seconds per rollout, in this process (one core; CPU time, not wall time, so a
   busy machine changes it little), of the same noisy 3 s sequences on the 9-obstacle
   Generalization II scene of seed 0 (``sto.throughput_sequences``), for every named rollout model,
   the models interleaved in each of ``--repeats`` passes; the speed-ups over ``full_5ms`` are
   paired per pass (their median is reported).
2. Agreement: the 48 validation sequences of ``sto.validation_sequences`` (noisy copies of both
   planners' initial sequences on the default scene, the throughput sequences, both planners'
   initial sequences with a noisy copy on Generalization I and II scenes) rolled out on every model
   and on the execution model (the world at the plant's time step, every object free); how many
   success verdicts agree, and how far apart the costs are; and the execution model's own verdict
   with the sequence's base nudged 1 um to either side (``--nudge``): a sequence whose verdict
   that flips is borderline for the verdict itself (``borderline``), no model can be held to it.

The models (``MODELS``): the full model at 5 ms (the issue's reference), the reduced model (objects
nothing comes near asleep) at 5 and 10 ms, the full model at 10 ms, each contact trim alone on the
reduced 10 ms model, the default trims at 10 and 20 ms (at 20 ms also with sampled output ports and
with the state read every 0.25 s), every one of them reading the state every 0.1 s otherwise, and
the default (``Scenario().optimiser``: 20 ms, read every 0.2 s). Writes ``DIR/rollout_models.json``
and ``DIR/rollout_models.png``.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import time
from pathlib import Path

import numpy as np
from sto import HORIZON, nudged, throughput_sequences, validation_sequences
from tqdm import tqdm

from hlp_drake.systems.optimiser.pool import SceneRollouts
from hlp_drake.systems.optimiser.rollout_world import RolloutWorld
from hlp_drake.systems.scenario import Scenario

UNTRIMMED = (
    "rollout_trims: {top_spheres: true, rim_spheres: 8, robot_self_contact: true, sampled_output_ports: true}"
)
EVERY_100MS = "rollout_sample_period: 0.1"
"""The state read every 0.1 s, as the execution model's (and every model's before the default's 0.2 s)."""
MODELS = {
    "full_5ms": f"{{rollout_time_step: 0.005, reduced_model: false, {UNTRIMMED}, {EVERY_100MS}}}",
    "reduced_5ms": f"{{rollout_time_step: 0.005, reduced_model: true, {UNTRIMMED}, {EVERY_100MS}}}",
    "full_10ms": f"{{rollout_time_step: 0.01, reduced_model: false, {UNTRIMMED}, {EVERY_100MS}}}",
    "reduced_10ms": f"{{rollout_time_step: 0.01, reduced_model: true, {UNTRIMMED}, {EVERY_100MS}}}",
    "reduced_10ms_bottom_spheres": "{rollout_time_step: 0.01, reduced_model: true, rollout_trims: "
    f"{{top_spheres: false, rim_spheres: 8, robot_self_contact: true, sampled_output_ports: true}}, {EVERY_100MS}}}",
    "reduced_10ms_rim4": "{rollout_time_step: 0.01, reduced_model: true, rollout_trims: "
    f"{{top_spheres: true, rim_spheres: 4, robot_self_contact: true, sampled_output_ports: true}}, {EVERY_100MS}}}",
    "reduced_10ms_no_self_contact": "{rollout_time_step: 0.01, reduced_model: true, rollout_trims: "
    f"{{top_spheres: true, rim_spheres: 8, robot_self_contact: false, sampled_output_ports: true}}, {EVERY_100MS}}}",
    "reduced_10ms_unsampled": "{rollout_time_step: 0.01, reduced_model: true, rollout_trims: "
    f"{{top_spheres: true, rim_spheres: 8, robot_self_contact: true, sampled_output_ports: false}}, {EVERY_100MS}}}",
    "trimmed_10ms": f"{{rollout_time_step: 0.01, {EVERY_100MS}}}",
    "trimmed_20ms": f"{{rollout_time_step: 0.02, {EVERY_100MS}}}",
    "trimmed_20ms_sampled": f"{{rollout_time_step: 0.02, rollout_trims: {{sampled_output_ports: true}}, {EVERY_100MS}}}",
    "trimmed_20ms_every_250ms": "{rollout_time_step: 0.02, rollout_sample_period: 0.25}",
    "default": "{}",
}


def model(scenario: Scenario, name: str) -> Scenario:
    """``scenario`` with the rollout model ``name``."""
    return scenario.updated(f"optimiser: {MODELS[name]}")


def throughput(names: list[str], count: int, repeats: int) -> dict:
    """CPU seconds per rollout of each model, interleaved per pass, on warm worlds (see the docstring)."""
    scene, config, sequences = throughput_sequences(count)
    rollouts = {name: SceneRollouts(model(config, name)) for name in names}
    for name in names:  # build every reduced world the sequences need
        for sequence in sequences:
            rollouts[name].rollout(sequence)
    passes = []
    for _ in tqdm(range(repeats), desc="throughput", unit="pass"):
        entry = {}
        for name in names:
            cpu, wall = time.process_time(), time.perf_counter()
            costs = [rollouts[name].rollout(s).cost for s in sequences]
            entry[name] = {
                "cpu_s_per_rollout": (time.process_time() - cpu) / count,
                "wall_s_per_rollout": (time.perf_counter() - wall) / count,
                "load": os.getloadavg()[0],
                "costs": costs,
            }
        passes.append(entry)
    summary = {"scene": scene.name, "objects": len(scene.objects), "horizon_s": HORIZON, "rollouts": count}
    for name in names:
        cpu = [p[name]["cpu_s_per_rollout"] for p in passes]
        summary[name] = {
            "cpu_s_per_rollout_median": float(np.median(cpu)),
            "rollouts_per_cpu_s": 1.0 / float(np.median(cpu)),
            "speedup_over_full_5ms_median": float(
                np.median([p["full_5ms"]["cpu_s_per_rollout"] / p[name]["cpu_s_per_rollout"] for p in passes])
            )
            if "full_5ms" in names
            else None,
            "same_costs_every_pass": all(p[name]["costs"] == passes[0][name]["costs"] for p in passes),
        }
    summary["passes"] = passes
    return summary


def agreement(names: list[str], count: int, scenes: int, nudge: float) -> dict:
    """Verdicts and costs of the validation sequences on every model against the execution model's,
    and (``nudge`` > 0) the execution model's verdicts of each sequence with the base ``nudge`` m to
    either side (``sto.nudged``): a sequence whose verdict that flips is borderline for the verdict itself."""
    triples = validation_sequences(count, scenes)
    cache: dict = {}

    def rollouts(scene, name: str | None, settle: bool) -> SceneRollouts | RolloutWorld:
        key = (id(scene), name, settle)
        if key not in cache:
            config = Scenario(scene=scene)
            if not settle:
                config = config.updated("optimiser: {settle_s: 0.0}")
            cache[key] = (
                RolloutWorld(config, execution=True) if name is None else SceneRollouts(model(config, name))
            )
        return cache[key]

    def entry(outcome) -> dict:
        return {
            "success": outcome.success,
            "cost": outcome.cost,
            "failure_reason": outcome.failure_reason,
            "target_distance": outcome.target_distance,
            "wall_s": outcome.wall_s,
        }

    rows = []
    for scene, label, sequence, settle in tqdm(triples, desc="agreement", unit="sequence"):
        row = {"sequence": label, "objects": len(scene.objects)}
        for name in (None, *names):
            row[name or "execution"] = entry(rollouts(scene, name, settle).rollout(sequence))
        if nudge > 0:  # the execution's own verdict with the base 1 um off to either side
            execution = rollouts(scene, None, settle)
            row["execution_nudged"] = [entry(execution.rollout(nudged(sequence, d))) for d in (nudge, -nudge)]
            row["borderline"] = any(
                n["success"] != row["execution"]["success"] for n in row["execution_nudged"]
            )
        rows.append(row)
    summary: dict = {
        "sequences": len(rows),
        "successes_execution": sum(r["execution"]["success"] for r in rows),
        "borderline": [r["sequence"] for r in rows if r.get("borderline")],
    }
    for name in names:
        gaps = [abs(r[name]["cost"] - r["execution"]["cost"]) for r in rows]
        summary[name] = {
            "verdicts_agree": int(sum(r[name]["success"] == r["execution"]["success"] for r in rows)),
            "disagreeing": [r["sequence"] for r in rows if r[name]["success"] != r["execution"]["success"]],
            "passed_here_failed_in_execution": int(
                sum(r[name]["success"] and not r["execution"]["success"] for r in rows)
            ),
            "cost_gap_median": float(np.median(gaps)),
            "cost_gap_p90": float(np.percentile(gaps, 90)),
        }
    summary["note"] = (
        "the settle-free throughput sequences settle 0 s on every model; the others settle as the "
        "execution does on the execution model and optimiser.settle_s on the rollout models"
    )
    summary["rows"] = rows
    return summary


def plot(report: dict, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = report["throughput"]
    names = [n for n in MODELS if n in t]
    fig, ax = plt.subplots(figsize=(8, 4))
    rates = [t[n]["rollouts_per_cpu_s"] for n in names]
    bars = ax.bar(range(len(names)), rates, color="tab:blue")
    a = report.get("agreement")
    for bar, n in zip(bars, names):
        label = f"{rates[names.index(n)]:.1f}/s"
        if a is not None and n in a:
            label += f"\n{a[n]['verdicts_agree']}/{a['sequences']}"
        ax.annotate(label, (bar.get_x() + bar.get_width() / 2, bar.get_height()), ha="center", va="bottom")
    ax.set_xticks(range(len(names)), names, rotation=30, ha="right")
    ax.set_ylabel("rollouts per CPU second (3 s, 9 objects)")
    ax.set_title("Rollout models: throughput per core (and verdicts agreeing with the execution model)")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--out", default="benchmark-results", help="output directory")
    parser.add_argument("--rollouts", type=int, default=8, help="throughput sequences per pass")
    parser.add_argument("--repeats", type=int, default=3, help="throughput passes")
    parser.add_argument("--sequences", type=int, default=8, help="agreement: noisy sequences per planner")
    parser.add_argument("--scenes", type=int, default=2, help="agreement: Generalization I and II scenes")
    parser.add_argument("--models", nargs="+", choices=list(MODELS), default=list(MODELS))
    parser.add_argument(
        "--agreement-models",
        nargs="+",
        choices=list(MODELS),
        default=["full_5ms", "reduced_5ms", "trimmed_10ms", "default"],
    )
    parser.add_argument(
        "--nudge", type=float, default=1e-6, help="agreement: the execution's own sensitivity, m (0: off)"
    )
    parser.add_argument("--skip-agreement", action="store_true")
    args = parser.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    names = list(dict.fromkeys(["full_5ms", *args.models]))
    report = {
        "machine": {
            "platform": platform.platform(),
            "cpus": os.cpu_count(),
            "python": platform.python_version(),
        },
        "load_before": os.getloadavg(),
        "models": {n: MODELS[n] for n in names},
        "throughput": throughput(names, args.rollouts, args.repeats),
    }
    for n in names:
        t = report["throughput"][n]
        print(
            f"{n}: {t['rollouts_per_cpu_s']:.2f} rollouts per CPU s, x{t['speedup_over_full_5ms_median']:.2f} "
            f"the full model at 5 ms (paired median)"
        )
    if not args.skip_agreement:
        checked = list(dict.fromkeys(args.agreement_models))
        report["agreement"] = a = agreement(checked, args.sequences, args.scenes, args.nudge)
        print(
            f"agreement with the execution model ({a['sequences']} sequences, {a['successes_execution']} pass; "
            f"borderline, the execution's verdict flipping under a {args.nudge:g} m nudge: {a['borderline']}):"
        )
        for n in checked:
            print(
                f"  {n}: {a[n]['verdicts_agree']}/{a['sequences']} verdicts agree, "
                f"{a[n]['passed_here_failed_in_execution']} passed here and failed there, "
                f"cost gap median {a[n]['cost_gap_median']:.3g}; disagreeing: {a[n]['disagreeing']}"
            )
    (out / "rollout_models.json").write_text(json.dumps(report, indent=2) + "\n")
    plot(report, out / "rollout_models.png")
    print(f"wrote {out / 'rollout_models.json'} and {out / 'rollout_models.png'}")


if __name__ == "__main__":
    main()
