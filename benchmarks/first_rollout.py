"""How often a planner's initial trajectory passes at its first rollout, before any optimisation.

    python benchmarks/first_rollout.py gen1 [--scenes 100] [--seed S] [--objects 5 7 9] [--planner hlp]
        [--config SCENARIO.yaml] [--workers 2] [--json OUT]

Plans each seeded scene, solves IK and rolls the initial trajectory out once, as the optimiser's
first rollout (``hlp_drake.systems.low_level.sto.first_rollout``: reduced model, rollout time step). Prints the
passes per object count and every failing scene with its reason. The optimiser stops at a passing
first rollout, so this count decides most of the planning time; comparing two configurations
(``--config`` with, say, ``motion: {closed_among_obstacles: false}``) shows what a planning or
motion rule does in a few minutes instead of a full experiment.
"""

from __future__ import annotations

import argparse
import json
import multiprocessing
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

from tqdm import tqdm

from hlp_drake.commands.parsing import run_cli
from hlp_drake.errors import HlpError
from hlp_drake.files.atomic import check_writable, write_text_atomic
from hlp_drake.scene.generators import generate_scene


def first_pass(kind: str, seed: int, objects: int | None, planner: str, config_yaml: str) -> dict:
    """One scene's first-rollout outcome as a JSON-ready row."""
    from dataclasses import replace

    from hlp_drake.learners.bundled import default_models
    from hlp_drake.systems.low_level.sto.first_rollout import first_rollout
    from hlp_drake.systems.planning.initialisers import initialiser_name
    from hlp_drake.systems.scenario import load_scenario

    scene = generate_scene(kind, seed, objects)
    settings = load_scenario(data=config_yaml)
    scenario = replace(
        settings, scene=scene, planner=replace(settings.planner, initial=initialiser_name(planner))
    )
    outcome = first_rollout(scenario, models=default_models())
    return {
        "scene": scene.name,
        "seed": seed,
        "objects": len(scene.obstacles),
        "passed": bool(outcome is not None and outcome.success),
        "reason": "no trajectory" if outcome is None else outcome.failure_reason,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("kind", choices=("vr", "gen1", "gen2"))
    parser.add_argument("--scenes", type=int, default=100)
    parser.add_argument("--seed", type=int, default=0, help="scene i has seed S + i")
    parser.add_argument("--objects", type=int, nargs="+", default=[5, 7, 9], help="gen2 object counts")
    parser.add_argument(
        "--planner", choices=("hlp", "line", "sto"), default="hlp", help="the initialiser (sto: line)"
    )
    parser.add_argument("--config", type=Path, help="scenario settings YAML (default: the defaults)")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--json", type=Path, help="write the rows and counts here")
    args = parser.parse_args()
    check_writable(args.json)
    from hlp_drake.systems.scenario import load_scenario

    try:
        config_yaml = load_scenario(args.config).yaml
    except HlpError as error:
        parser.error(str(error))
    counts = args.objects if args.kind == "gen2" else [None]
    jobs = [
        (args.kind, args.seed + i, n, args.planner, config_yaml) for n in counts for i in range(args.scenes)
    ]
    started = time.perf_counter()
    with ProcessPoolExecutor(args.workers, mp_context=multiprocessing.get_context("spawn")) as pool:
        outcomes = pool.map(first_pass, *zip(*jobs))
        rows = list(tqdm(outcomes, total=len(jobs), desc="first rollouts", unit="scene"))
    summary = {}
    for n in counts:
        group = [r for r in rows if n is None or r["objects"] == n]
        label = args.kind if n is None else f"{args.kind}, {n} objects"
        summary[label] = {"passed": sum(r["passed"] for r in group), "scenes": len(group)}
        print(f"{label} ({args.planner}): {summary[label]['passed']}/{len(group)} pass at the first rollout")
        for r in group:
            if not r["passed"]:
                print(f"  {r['scene']}: {r['reason']}")
    print(f"{time.perf_counter() - started:.0f} s wall on {args.workers} workers")
    if args.json is not None:
        write_text_atomic(args.json, json.dumps({"summary": summary, "rows": rows}, indent=1))


if __name__ == "__main__":
    raise SystemExit(run_cli(lambda _argv: main() or 0))  # bad paths: one line, exit 2
