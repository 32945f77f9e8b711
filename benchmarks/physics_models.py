"""Which execution model: the fastest physics setting that agrees with a fine reference.

    python benchmarks/physics_models.py [--out DIR] [--models trimmed_20ms ...] [--nudge 3e-5]
        [--sequences 4] [--scenes 2] [--workers 2]

The reference is the full model (today's contact geometry: support spheres on every corner and 8 per
rim, the robot's self-contact) at a 1 ms step. Every model rolls out the 48 validation sequences of
``sto.validation_sequences`` as the execution does (every object awake, settling as the execution
does, the state read every ``optimiser.sample_period``). The reference also rolls each sequence out
with the base nudged ``--nudge`` m to either side (``sto.nudged``; 0.03 mm, the chaos floor): the
spread of its own final object centres and whether its verdict flips (a *borderline* sequence).

A model **agrees** on a sequence when its success verdict is the reference's (or the sequence is
borderline) and every object's final centre is within the reference's own nudged spread of the
reference's, or within ``--floor`` m (default 2 mm: an object at rest on the table sags and creeps by
fractions of a millimetre per step size, and the cost's disturbance terms do not resolve less);
``poses_within_twice`` loosens that to twice the spread or 2.5 floors.

Before that, the **rest check**: every candidate holds the robot still for 4 s on Gen I scenes and
Gen II scenes with 9 objects; an object that moves more than 1 mm has not stayed at rest.

Besides, the CPU seconds each model took per simulated second (the same rollouts, each in the
process that ran it; CPU time, so other load changes it little). Writes ``DIR/physics_models.json``
and ``DIR/physics_models.png``.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import time
from concurrent.futures import ProcessPoolExecutor
from functools import cache
from pathlib import Path

import numpy as np
from sto import nudged, validation_sequences
from tqdm import tqdm

from hlp_drake.commands.parsing import run_cli
from hlp_drake.files.atomic import atomic_path, check_folder, write_text_atomic
from hlp_drake.scene.generators import generate_scene
from hlp_drake.systems.low_level.control_sequence import ControlSequence
from hlp_drake.systems.low_level.sto.rollout_world import RolloutWorld
from hlp_drake.systems.low_level.sto.spec import RolloutSpec
from hlp_drake.systems.scenario import Scenario

FULL = "contact: {top_spheres: true, rim_spheres: 8, robot_self_contact: true}"
"""The full contact geometry: support spheres on every corner, 8 per rim, the robot's self-contact."""
TRIMS = "contact: {top_spheres: false, rim_spheres: 4, robot_self_contact: false}"
"""The contact trims (the default since issue 39): support spheres on the bottom corners and rims
only, 4 per rim, no self-contact."""


def _model(step: float, contact: str, sampled: bool = False) -> str:
    return f"plant: {{time_step: {step}, use_sampled_output_ports: {str(sampled).lower()}}}\n{contact}"


MODELS = {
    "reference_1ms": _model(0.001, FULL, sampled=True),
    "full_2ms": _model(0.002, FULL, sampled=True),
    "trimmed_2ms": _model(0.002, TRIMS),
    "trimmed_5ms": _model(0.005, TRIMS),
    "trimmed_10ms": _model(0.01, TRIMS),
}
"""The world's physics settings compared (``full_2ms``: the execution model before issue 39;
``trimmed_10ms``: the default since). Steps above 10 ms are refused when a scenario loads (resting
cylinders walk off the table at 15 and 20 ms: ``rest_check``); the 20 ms rows of docs/results.md were
measured before that bound, at commit daf8202."""
REST_S = 4.0
"""How long the robot holds still in the rest check, s."""
MOVED = 0.001
"""An object at rest that moves further than this in the rest check has not stayed at rest, m."""
REFERENCE = "reference_1ms"
SETTLE_S = 1.0
"""Settling after a sequence, s (as the execution did before issue 39, and every model does since)."""


@cache
def _triples(count: int, scenes: int) -> list[tuple]:
    return validation_sequences(count, scenes)


@cache
def _world(index: int, count: int, scenes: int, name: str) -> RolloutWorld:
    scene, _, _, settle = _triples(count, scenes)[index]
    settle_s = SETTLE_S if settle else 0.0
    config = Scenario(scene=scene).updated(f"{MODELS[name]}\nsuccess: {{settle_s: {settle_s}}}")
    return RolloutWorld(RolloutSpec.of(config))


def _entry(world: RolloutWorld, sequence) -> dict:
    cpu = time.process_time()
    outcome = world.rollout(sequence)
    cpu = time.process_time() - cpu
    final = outcome.prediction.positions[-1] if outcome.prediction is not None else None
    return {
        "success": outcome.success,
        "cost": outcome.cost,
        "failure_reason": outcome.failure_reason,
        "target_distance": outcome.target_distance,
        "simulated_s": outcome.simulated_s,
        "cpu_s": cpu,
        "final": None if final is None else final.tolist(),
    }


def _sequence_task(index: int, count: int, scenes: int, names: tuple[str, ...], nudge: float) -> dict:
    """Every model's rollout of validation sequence ``index``, and the reference's nudged ones."""
    scene, label, sequence, _ = _triples(count, scenes)[index]
    row = {"sequence": label, "objects": len(scene.objects), "duration_s": sequence.duration}
    for name in names:
        row[name] = _entry(_world(index, count, scenes, name), sequence)
    if nudge > 0:
        reference = _world(index, count, scenes, REFERENCE)
        row["reference_nudged"] = [_entry(reference, nudged(sequence, d)) for d in (nudge, -nudge)]
    return row


def _rest_task(kind: str, seed: int, names: tuple[str, ...]) -> dict:
    """Per model, on the scene ``kind`` of ``seed`` (9 objects for gen2) with the robot holding still
    for ``REST_S``: how far the furthest object moved, m, and how many moved more than ``MOVED``."""
    scene = generate_scene(kind, seed, 9 if kind == "gen2" else None)
    row = {"scene": scene.name}
    for name in names:
        world = RolloutWorld(RolloutSpec.of(Scenario(scene=scene).updated(MODELS[name])))
        start = world.start_positions
        outcome = world.rollout(ControlSequence(np.array([0.0, REST_S]), np.vstack([start, start])))
        positions = outcome.prediction.positions
        moved = np.linalg.norm(positions[-1] - positions[0], axis=1)
        row[name] = {"max_drift_m": float(np.max(moved)), "moved": int(np.sum(moved > MOVED))}
    return row


def rest_check(pool: ProcessPoolExecutor, names: tuple[str, ...], scenes: int) -> dict:
    """Every model holding the robot still on Gen I scenes and Gen II scenes with 9 objects (seeds
    0..scenes-1 each): objects at rest must stay there."""
    futures = [
        pool.submit(_rest_task, kind, seed, names) for kind in ("gen1", "gen2") for seed in range(scenes)
    ]
    rows = [f.result() for f in tqdm(futures, desc="rest check", unit="scene")]
    return {
        "scenes": len(rows),
        "hold_s": REST_S,
        **{
            name: {
                "objects_moved": int(sum(r[name]["moved"] for r in rows)),
                "scenes_with_a_moved_object": int(sum(r[name]["moved"] > 0 for r in rows)),
                "max_drift_m": float(max(r[name]["max_drift_m"] for r in rows)),
            }
            for name in names
        },
        "rows": rows,
    }


def _gap(a: dict, b: dict) -> float:
    """Largest distance between two rollouts' final object centres, m (inf where one has none)."""
    if a["final"] is None or b["final"] is None:
        return float("inf")
    return float(np.max(np.linalg.norm(np.array(a["final"]) - np.array(b["final"]), axis=1)))


def summarise(rows: list[dict], names: list[str], floor: float) -> dict:
    """Per model: verdicts and poses agreeing with the reference (see the module's docstring)."""
    for row in rows:
        ref = row[REFERENCE]
        nudges = row.get("reference_nudged", [])
        row["borderline"] = any(n["success"] != ref["success"] for n in nudges)
        row["spread_m"] = max((_gap(n, ref) for n in nudges), default=0.0)
    summary: dict = {
        "sequences": len(rows),
        "successes_reference": int(sum(r[REFERENCE]["success"] for r in rows)),
        "borderline": [r["sequence"] for r in rows if r["borderline"]],
        "floor_m": floor,
        "spread_m_median": float(np.median([r["spread_m"] for r in rows])),
        "spread_m_max": float(np.max([r["spread_m"] for r in rows])),
    }
    for name in names:
        verdicts = [r[name]["success"] == r[REFERENCE]["success"] or r["borderline"] for r in rows]
        gaps = [_gap(r[name], r[REFERENCE]) for r in rows]
        poses = [g <= max(r["spread_m"], floor) for g, r in zip(gaps, rows)]
        loose = [g <= max(2 * r["spread_m"], 2.5 * floor) for g, r in zip(gaps, rows)]
        simulated = sum(r[name]["simulated_s"] for r in rows)
        summary[name] = {
            "verdicts_agree": int(sum(verdicts)),
            "strict_verdicts_agree": int(sum(r[name]["success"] == r[REFERENCE]["success"] for r in rows)),
            "poses_agree": int(sum(poses)),
            "poses_within_twice": int(sum(loose)),
            "both_agree": int(sum(v and p for v, p in zip(verdicts, poses))),
            "disagreeing": [r["sequence"] for r, v, p in zip(rows, verdicts, poses) if not (v and p)],
            "passed_here_failed_in_reference": [
                r["sequence"] for r in rows if r[name]["success"] and not r[REFERENCE]["success"]
            ],
            "successes": int(sum(r[name]["success"] for r in rows)),
            "pose_gap_m_median": float(np.median(gaps)),
            "pose_gap_m_p90": float(np.percentile(gaps, 90)),
            "cpu_s_per_simulated_s": sum(r[name]["cpu_s"] for r in rows) / simulated,
        }
    return summary


def plot(summary: dict, names: list[str], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 4))
    costs = [summary[n]["cpu_s_per_simulated_s"] * 1000 for n in names]
    bars = ax.bar(
        range(len(names)), costs, color=["tab:grey" if n == REFERENCE else "tab:blue" for n in names]
    )
    for bar, n in zip(bars, names):
        label = f"{summary[n]['both_agree']}/{summary['sequences']}"
        ax.annotate(label, (bar.get_x() + bar.get_width() / 2, bar.get_height()), ha="center", va="bottom")
    ax.set_xticks(range(len(names)), names, rotation=30, ha="right")
    ax.set_ylabel("CPU ms per simulated second")
    ax.set_yscale("log")
    ax.set_title("Execution models: cost, and sequences agreeing with the 1 ms reference")
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=120)
    plt.close(fig)


OUTPUTS = ("rest_check.json", "physics_models.json", "physics_models.png")
"""The files of --out."""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("physics-models"))
    parser.add_argument("--models", nargs="+", default=[n for n in MODELS if n != REFERENCE], choices=MODELS)
    parser.add_argument("--nudge", type=float, default=3e-5, help="the reference's nudge, m (0: none)")
    parser.add_argument("--floor", type=float, default=0.002, help="pose agreement floor, m")
    parser.add_argument("--sequences", type=int, default=8, help="noisy copies per planner (default scene)")
    parser.add_argument("--scenes", type=int, default=2, help="Gen I and Gen II scenes")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--rest-scenes", type=int, default=30, help="Gen I and Gen II scenes held at rest")
    parser.add_argument("--skip-agreement", action="store_true", help="only the rest check")
    parser.add_argument("--resummarise", type=Path, help="summarise this run's JSON again (no rollouts)")
    args = parser.parse_args()
    if args.resummarise is not None:
        report = json.loads(args.resummarise.read_text())
        report["summary"] = summarise(report["rows"], list(report["models"]), args.floor)
        write_text_atomic(args.resummarise, json.dumps(report, indent=1))
        return
    check_folder(args.out, *OUTPUTS).mkdir(exist_ok=True)
    names = (REFERENCE, *args.models)
    count = len(_triples(args.sequences, args.scenes))
    load = os.getloadavg()
    with ProcessPoolExecutor(args.workers) as pool:
        rest = rest_check(pool, tuple(args.models), args.rest_scenes)
        rows = []
        if not args.skip_agreement:
            futures = [
                pool.submit(_sequence_task, i, args.sequences, args.scenes, names, args.nudge)
                for i in range(count)
            ]
            rows = [f.result() for f in tqdm(futures, desc="sequences", unit="sequence")]
    print(f"rest check, {rest['scenes']} scenes held still {REST_S:g} s: objects moved > {MOVED * 1000:g} mm")
    for n in args.models:
        r = rest[n]
        print(f"  {n}: {r['objects_moved']} (max drift {1000 * r['max_drift_m']:.2f} mm)")
    if args.skip_agreement:
        write_text_atomic(
            args.out / "rest_check.json", json.dumps({"load": load, "rest_check": rest}, indent=1)
        )
        return
    summary = summarise(rows, list(names), args.floor)
    report = {
        "machine": {"platform": platform.platform(), "cpus": os.cpu_count(), "load_before": load},
        "load_after": os.getloadavg(),
        "models": {n: MODELS[n] for n in names},
        "nudge_m": args.nudge,
        "rest_check": rest,
        "summary": summary,
        "rows": rows,
    }
    write_text_atomic(args.out / "physics_models.json", json.dumps(report, indent=1))
    plot(summary, list(names), args.out / "physics_models.png")
    print(
        f"{summary['sequences']} sequences; reference successes {summary['successes_reference']}; "
        f"borderline {summary['borderline']}; reference spread median {summary['spread_m_median']:.2e} m"
    )
    print("| model | verdicts | poses | both | CPU ms / simulated s | x reference |")
    ref = summary[REFERENCE]["cpu_s_per_simulated_s"]
    for n in names:
        s = summary[n]
        print(
            f"| {n} | {s['verdicts_agree']} | {s['poses_agree']} | {s['both_agree']} | "
            f"{1000 * s['cpu_s_per_simulated_s']:.0f} | {ref / s['cpu_s_per_simulated_s']:.1f} |"
        )


if __name__ == "__main__":
    raise SystemExit(run_cli(lambda _argv: main() or 0))  # bad paths: one line, exit 2
