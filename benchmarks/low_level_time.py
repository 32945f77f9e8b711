"""Planning time alone (no execution) of the kinematic low-level planners with either initialiser.

    python benchmarks/low_level_time.py [--kind gen2] [--objects 9] [--scenes 100] [--seed 0]
        [--planners trajopt rrt] [--out DIR]   (--objects: gen2 only)

For each scene (the experiments' seeds) and each low-level planner, both initialisers are timed
side by side in this one process: init (the plan and the keypoint IK) and the low-level planner,
evaluated on the planning diagram (``make_planning_diagram``), with the planner's success and
iterations. Reports medians and means per cell; writes ``DIR/low_level_time.json`` and
``DIR/low_level_time.csv``.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import time
from pathlib import Path

import pandas as pd
from tqdm import tqdm

from hlp_drake.commands.parsing import drake_logging, run_cli
from hlp_drake.files.atomic import check_folder, write_text_atomic
from hlp_drake.scene.generators import generate_scene
from hlp_drake.systems.conditions import Conditions
from hlp_drake.systems.planning.diagram import make_planning_diagram
from hlp_drake.systems.scenario import Scenario

OUTPUTS = ("low_level_time.json", "low_level_time.csv")


def _timed(scene, initial: str, low_level: str) -> dict:
    scenario = Conditions(initial=initial, low_level=low_level).applied(Scenario(), scene=scene)
    diagram = make_planning_diagram(scenario)
    context = diagram.CreateDefaultContext()
    diagram.GetInputPort("scene").FixValue(context, scene)
    started = time.perf_counter()
    diagram.GetOutputPort("trajectory").Eval(context)  # the plan, then the keypoint IK
    planned = time.perf_counter()
    result = diagram.GetOutputPort("optimisation").Eval(context)
    done = time.perf_counter()
    return {
        "scene": scene.name,
        "initial": initial,
        "low_level": low_level,
        "init_s": planned - started,
        "low_level_s": done - planned,
        "total_s": done - started,
        "success": result.success,
        "iterations": result.iterations,
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--kind", default="gen2")
    parser.add_argument("--objects", type=int, default=None, help="gen2: 5, 7, 9 (gen1: 6, fixed)")
    parser.add_argument("--scenes", type=int, default=100)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--planners", nargs="+", default=["trajopt", "rrt"])
    parser.add_argument("--out", type=Path, default=Path("benchmark-results"))
    args = parser.parse_args(argv)
    check_folder(args.out, *OUTPUTS).mkdir(exist_ok=True)
    drake_logging(False)  # Drake's INFO lines off, as the commands have them
    rows = []
    for seed in tqdm(range(args.seed, args.seed + args.scenes), unit=" scenes"):
        scene = generate_scene(args.kind, seed, args.objects)
        for low_level in args.planners:
            for initial in ("hlp", "line"):
                rows.append(_timed(scene, initial, low_level))
    table = pd.DataFrame(rows)
    cells = (
        table.groupby(["low_level", "initial"])
        .agg(
            scenes=("scene", "size"),
            init_median_s=("init_s", "median"),
            low_level_median_s=("low_level_s", "median"),
            total_median_s=("total_s", "median"),
            total_mean_s=("total_s", "mean"),
            accepted=("success", "sum"),
            iterations_mean=("iterations", "mean"),
        )
        .reset_index()
    )
    report = {
        "machine": {"cpus": os.cpu_count(), "python": platform.python_version()},
        "load_before": os.getloadavg(),
        "kind": args.kind,
        "objects": args.objects,
        "cells": cells.to_dict(orient="records"),
    }
    write_text_atomic(args.out / OUTPUTS[0], json.dumps(report, indent=1, default=float))
    write_text_atomic(args.out / OUTPUTS[1], table.to_csv(index=False, float_format="%.5f"))
    print(cells.to_string(index=False, float_format=lambda v: f"{v:.3f}"))
    print(f"wrote {', '.join(str(args.out / name) for name in OUTPUTS)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(run_cli(main))  # bad paths: one line, exit 2
