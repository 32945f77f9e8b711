"""``python -m hlp_drake.run_scene``: plan a scene, solve IK and execute it in the Drake world.

    python -m hlp_drake.run_scene [--scene FILE | --kind vr|gen1|gen2|unstructured --seed N [--objects K]]
        [--planner hlp|sto] [--meshcat] [--html FILE] [--json FILE] [--config WORLD.yaml]

With no arguments it runs the bundled default scene with the bundled models.
"""

from __future__ import annotations

import argparse
import json
import time
from collections.abc import Sequence
from pathlib import Path

from hlp_drake.atomic import write_text_atomic
from hlp_drake.cli import run_cli
from hlp_drake.errors import HlpError
from hlp_drake.scene.generators import KINDS, generate_scene
from hlp_drake.scene.io import load_scene
from hlp_drake.scene.validation import validate_scene

DEFAULT_SCENE = Path(__file__).resolve().parent / "scenes" / "default.yaml"


def summary(result) -> str:
    plan = result.plan
    steps = " -> ".join(
        k.action + (f" {k.element}" if k.action in ("gap", "move") else "") + (f" {k.direction}" if k.action == "move" else "")
        for k in plan.keypoints) or "(none)"
    t = result.timings
    start = (result.optimisation or {}).get("start", 0)
    alternative = f", from the planner's alternative {start}" if start else ""
    optimiser = (f"optimise {t['optimise_s']:.1f} s ({result.iterations} iterations, "
                 f"{result.rollouts} rollouts{alternative})" if result.rollouts else "not optimised")
    grasp = {None: "not attempted", True: "held", False: "did not hold"}[result.grasp_held]
    lines = [
        f"scene {result.scene.name}: {len(result.scene.obstacles)} obstacles, planner {result.planner}",
        f"plan: {steps}",
        (f"timings: plan {t['plan_s']:.3f} s, IK {t['ik_s']:.2f} s, {optimiser}, execute {t['execute_s']:.1f} s "
         f"({result.simulated_s:.1f} s simulated), total {t['total_s']:.1f} s"),
        f"objects moved: {', '.join(result.objects_moved) or 'none'}; dropped: {', '.join(result.objects_dropped) or 'none'}",
        "success" if result.success else f"failure: {result.failure_reason}",
        f"grasp: {grasp}",
    ]
    return "\n".join(lines)


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m hlp_drake.run_scene", description=__doc__.split("\n")[0])
    source = parser.add_mutually_exclusive_group()
    source.add_argument("--scene", help="a scene file (YAML or JSON); default: the bundled default scene")
    source.add_argument("--kind", choices=KINDS, help="generate a scene of this kind (with --seed)")
    parser.add_argument("--seed", type=int, default=0, help="seed of the generated scene (default 0)")
    parser.add_argument("--objects", type=int, help="number of obstacles (gen2 / unstructured)")
    parser.add_argument("--planner", choices=("hlp", "sto"), default="hlp",
                        help="initialise the trajectory optimiser with the human-like plan (hlp) or with "
                             "the baseline's straight line (sto)")
    parser.add_argument("--workers", type=int, help="rollout processes of the optimiser (default: the config's sto.workers)")
    parser.add_argument("--config", help="world configuration YAML (WorldConfig)")
    parser.add_argument("--meshcat", action="store_true", help="show the run live in MeshCat (prints the URL)")
    parser.add_argument("--html", help="write a self-contained MeshCat recording of the run")
    parser.add_argument("--json", help="write the result as JSON")
    args = parser.parse_args(argv)
    if args.kind is not None:
        scene = generate_scene(args.kind, args.seed, args.objects)
    else:
        scene = load_scene(args.scene or DEFAULT_SCENE)
    validate_scene(scene)

    from hlp_drake.systems.execution import plan_and_execute  # Drake is imported only here
    from hlp_drake.systems.world_config import WorldConfig, load_world_config

    config = load_world_config(args.config) if args.config else WorldConfig()
    if args.workers is not None:
        if args.workers < 1:
            raise HlpError(f"--workers must be >= 1, got {args.workers}")
        config.sto.workers = args.workers
    meshcat = None
    if args.meshcat or args.html:
        from pydrake.geometry import Meshcat, MeshcatParams

        meshcat = Meshcat(MeshcatParams(host="localhost"))
        if args.meshcat:
            print(f"MeshCat: {meshcat.web_url()}")
    started = time.perf_counter()
    result = plan_and_execute(scene, planner=args.planner, config=config, meshcat=meshcat, html=args.html)
    print(summary(result))
    if args.html:
        print(f"wrote {args.html}")
    if args.json:
        write_text_atomic(args.json, json.dumps(result.to_dict(), indent=2) + "\n")
        print(f"wrote {args.json}")
    if args.meshcat:
        print(f"done in {time.perf_counter() - started:.1f} s; MeshCat keeps serving until you press Ctrl-C")
        try:
            while True:
                time.sleep(1.0)
        except KeyboardInterrupt:
            pass
    return 0 if result.success else 1


if __name__ == "__main__":
    raise SystemExit(run_cli(main))
