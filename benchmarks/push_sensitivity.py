"""How far a push's outcome hinges on details no camera sees: one planner's initial sequence on
the execution model of a scene and of variants of it (its obstacles listed in other orders,
displaced by 0.1 and 1 mm, and the scene the default camera perceives).

    python benchmarks/push_sensitivity.py [--seed 33] [--objects 9] [--planner sto] [--csv OUT]

Prints and writes one row per variant: whether the rollout (on the reduced model where
``optimiser.reduced_model`` is on) and the execution model pass,
the execution model's cost and failure reason.
"""

from __future__ import annotations

import argparse
import csv
import dataclasses
import math
import sys
import time

import numpy as np

from hlp_drake.commands.parsing import run_cli
from hlp_drake.files.atomic import atomic_path, check_writable
from hlp_drake.scene.generators import generate_scene
from hlp_drake.systems.low_level.sto.first_rollout import initial_sequence
from hlp_drake.systems.low_level.sto.pool import SceneRollouts
from hlp_drake.systems.low_level.sto.spec import RolloutSpec
from hlp_drake.systems.perception.system import perceive_world
from hlp_drake.systems.scenario import Scenario
from hlp_drake.systems.world.uncertainty import displaced_scenes


def variants(scene, scenario: Scenario) -> dict:
    """The scene, its obstacles reversed and twice permuted (seeded), displaced twice by 0.1 and
    by 1 mm (0.05 and 0.5 degrees), and as perceived."""
    rng = np.random.default_rng(0)
    result = {"as generated": scene, "reversed": dataclasses.replace(scene, obstacles=scene.obstacles[::-1])}
    for k in range(2):
        order = rng.permutation(len(scene.obstacles))
        result[f"permuted {k + 1}"] = dataclasses.replace(
            scene, obstacles=tuple(scene.obstacles[i] for i in order)
        )
    for sigma in (0.0001, 0.001):
        for k, moved in enumerate(displaced_scenes(scene, 2, sigma, math.radians(500 * sigma))):
            result[f"displaced {sigma * 1000:g} mm {k + 1}"] = moved
    result["perceived"] = perceive_world(scenario)[0].scene
    return result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--seed", type=int, default=33)
    parser.add_argument("--objects", type=int, default=9)
    parser.add_argument(
        "--planner", choices=("hlp", "line", "sto"), default="line", help="the initialiser (sto: line)"
    )
    parser.add_argument("--csv")
    args = parser.parse_args()
    check_writable(args.csv)
    scene = generate_scene("gen2", args.seed, args.objects)
    scenario = Scenario(scene=scene).updated(f"planner: {{initial: {args.planner}}}")
    sequence = initial_sequence(scenario)
    if sequence is None:
        sys.exit(f"{scene.name}: the {args.planner} planner gives no initial trajectory")
    rows = []
    for name, variant in variants(scene, scenario).items():
        started = time.perf_counter()
        world = SceneRollouts(RolloutSpec.of(dataclasses.replace(scenario, scene=variant)))
        rolled, verified = world.rollout(sequence), world.verify(sequence)
        rows.append(
            {
                "variant": name,
                "rollout_success": rolled.success,
                "execution_success": verified.success,
                "execution_cost": round(verified.cost, 3),
                "failure_reason": verified.failure_reason or "",
                "seconds": round(time.perf_counter() - started, 1),
            }
        )
        print(*rows[-1].values(), sep="  ", flush=True)
    if args.csv:
        with atomic_path(args.csv) as tmp, tmp.open("w", newline="") as f:
            writer = csv.DictWriter(f, fieldnames=list(rows[0]))
            writer.writeheader()
            writer.writerows(rows)
    passed = sum(r["execution_success"] for r in rows)
    print(f"{passed} of {len(rows)} variants pass on the execution model", file=sys.stderr)


if __name__ == "__main__":
    raise SystemExit(run_cli(lambda _argv: main() or 0))  # bad paths: one line, exit 2
