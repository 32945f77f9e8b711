"""Which world judges: the accepted plans' verdicts in finer physics, against a 0.5 ms run.

    python benchmarks/world_judges.py [--out DIR] [--gen1 30] [--gen2 25] [--objects 9] [--seed 7000]
        [--worlds fine_0.5ms reference_1ms full_2ms trimmed_2ms] [--config SCENARIO.yaml] [--workers 2]

Plans fresh scenes (Generalization I and II, seeds from ``--seed``: scenes no setting was tuned
on) with both initialisers and the low-level planner in its own model (``world: model``, open
loop). Every plan the planner accepted is then rolled out from the scene's start in each world of
``--worlds`` (``WorldConfig``: step, contact geometry, sampled ports), settling as the execution
does, and judged by the success test itself (no acceptance margin). Reports, per world, the
verdicts agreeing with ``fine_0.5ms`` (a world is converged when it agrees on at least 99 %), the
accepted plans it fails (the model's false accepts, judged there), and the CPU seconds per
simulated second. Writes ``DIR/world_judges.json`` and ``DIR/world_judges.png``.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import replace
from pathlib import Path

from tqdm import tqdm

from hlp_drake.commands.parsing import run_cli
from hlp_drake.files.atomic import atomic_path, check_folder, write_text_atomic
from hlp_drake.scene.generators import generate_scene
from hlp_drake.systems.conditions import Conditions
from hlp_drake.systems.execution.run import RunListener, plan_and_execute
from hlp_drake.systems.low_level.sto.first_rollout import sto_config
from hlp_drake.systems.low_level.sto.pool import RolloutPool
from hlp_drake.systems.low_level.sto.rollout_world import RolloutWorld
from hlp_drake.systems.low_level.sto.spec import RolloutSpec
from hlp_drake.systems.scenario import Scenario, load_scenario
from hlp_drake.systems.world.judge import WorldConfig

TRIMMED = {"top_spheres": False, "rim_spheres": 4, "robot_self_contact": False, "sampled_ports": False}
WORLDS = {
    "fine_0.5ms": WorldConfig(time_step=0.0005),
    "reference_1ms": WorldConfig(),
    "full_2ms": WorldConfig(time_step=0.002),
    "trimmed_2ms": WorldConfig(time_step=0.002, **TRIMMED),
    "trimmed_5ms": WorldConfig(time_step=0.005, **TRIMMED),
}
"""The worlds compared (``fine_0.5ms``: the convergence reference; ``reference_1ms``: ``world:
reference``)."""
FINE = "fine_0.5ms"


class _Capture(RunListener):
    def __init__(self) -> None:
        self.result = None

    def optimised(self, result) -> None:
        self.result = result


def _task(
    kind: str, seed: int, objects: int | None, initial: str, names: tuple[str, ...], config: str
) -> dict:
    """Plan the scene in the model; roll an accepted plan out in every world of ``names``."""
    scene = generate_scene(kind, seed, objects)
    base = load_scenario(data=config) if config else Scenario()
    scenario = Conditions(initial=initial, world="model", execution="open", workers=1).applied(
        base, scene=scene
    )
    capture = _Capture()
    started = time.perf_counter()
    with RolloutPool(1) as pool:
        run = plan_and_execute(scenario, pool=pool, listener=capture)
    row = {
        "scene": scene.name,
        "initial": initial,
        "model_success": bool(capture.result is not None and capture.result.success),
        "model_reason": run.failure_reason,
        "rollouts": run.rollouts,
        "plan_s": time.perf_counter() - started,
    }
    if not row["model_success"]:
        return row
    sto = replace(sto_config(scenario), acceptance_margin=0.0)  # the test itself judges
    for name in names:
        spec = RolloutSpec(scene, WORLDS[name].of(scenario.world_model), sto, scenario.success)
        cpu = time.process_time()
        outcome = RolloutWorld(spec).rollout(capture.result.sequence)
        row[name] = {
            "success": outcome.success,
            "failure_reason": outcome.failure_reason,
            "simulated_s": outcome.simulated_s,
            "cpu_s": time.process_time() - cpu,
        }
    return row


def summarise(rows: list[dict], names: list[str]) -> dict:
    accepted = [r for r in rows if r["model_success"]]
    summary: dict = {"jobs": len(rows), "accepted": len(accepted)}
    for name in names:
        agree = [r[name]["success"] == r[FINE]["success"] for r in accepted] if FINE in names else []
        simulated = sum(r[name]["simulated_s"] for r in accepted) or 1.0
        summary[name] = {
            "successes": int(sum(r[name]["success"] for r in accepted)),
            "false_accepts": [f"{r['scene']} {r['initial']}" for r in accepted if not r[name]["success"]],
            "verdicts_agree_with_fine": int(sum(agree)),
            "agree_fraction": (sum(agree) / len(agree)) if agree else None,
            "disagreeing": [f"{r['scene']} {r['initial']}" for r, a in zip(accepted, agree) if not a],
            "cpu_s_per_simulated_s": sum(r[name]["cpu_s"] for r in accepted) / simulated,
        }
    return summary


def plot(summary: dict, names: list[str], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 4))
    costs = [summary[n]["cpu_s_per_simulated_s"] * 1000 for n in names]
    bars = ax.bar(range(len(names)), costs, color=["tab:grey" if n == FINE else "tab:blue" for n in names])
    for bar, n in zip(bars, names):
        s = summary[n]
        label = f"agree {s['verdicts_agree_with_fine']}/{summary['accepted']}\npass {s['successes']}"
        ax.annotate(label, (bar.get_x() + bar.get_width() / 2, bar.get_height()), ha="center", va="bottom")
    ax.set_xticks(range(len(names)), names)
    ax.set_ylabel("CPU ms per simulated second")
    ax.set_title(f"Worlds judging {summary['accepted']} accepted plans, against {FINE}")
    ax.margins(y=0.25)
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=120)
    plt.close(fig)


OUTPUTS = ("world_judges.json", "world_judges.png")
"""The files of --out."""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("world-judges"))
    parser.add_argument("--gen1", type=int, default=30, help="Generalization I scenes")
    parser.add_argument("--gen2", type=int, default=25, help="Generalization II scenes")
    parser.add_argument("--objects", type=int, default=9, help="Generalization II's obstacles")
    parser.add_argument("--seed", type=int, default=7000, help="the first scene's seed")
    parser.add_argument("--worlds", nargs="+", default=list(WORLDS)[:4], choices=WORLDS)
    parser.add_argument(
        "--config", type=Path, help="scenario settings of the planner (default: the defaults)"
    )
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    check_folder(args.out, *OUTPUTS).mkdir(exist_ok=True)
    config = args.config.read_text() if args.config else ""
    names = tuple(args.worlds)
    jobs = [("gen1", args.seed + i, None) for i in range(args.gen1)]
    jobs += [("gen2", args.seed + i, args.objects) for i in range(args.gen2)]
    load = os.getloadavg()
    with ProcessPoolExecutor(args.workers) as pool:
        futures = [
            pool.submit(_task, kind, seed, objects, initial, names, config)
            for kind, seed, objects in jobs
            for initial in ("hlp", "line")
        ]
        rows = [f.result() for f in tqdm(futures, desc="plans", unit="plan")]
    summary = summarise(rows, list(names))
    report = {
        "machine": {"platform": platform.platform(), "cpus": os.cpu_count(), "load_before": load},
        "load_after": os.getloadavg(),
        "worlds": {n: WORLDS[n].__dict__ for n in names},
        "config": config,
        "summary": summary,
        "rows": rows,
    }
    write_text_atomic(args.out / "world_judges.json", json.dumps(report, indent=1))
    plot(summary, list(names), args.out / "world_judges.png")
    print(f"{summary['accepted']} accepted plans of {summary['jobs']}")
    print("| world | passes | agrees with 0.5 ms | CPU ms / simulated s |")
    for n in names:
        s = summary[n]
        print(
            f"| {n} | {s['successes']} | {s['verdicts_agree_with_fine']} | "
            f"{1000 * s['cpu_s_per_simulated_s']:.0f} |"
        )


if __name__ == "__main__":
    raise SystemExit(run_cli(lambda _argv: main() or 0))  # bad paths: one line, exit 2
