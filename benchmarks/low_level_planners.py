"""Every low-level planner on the default scene, end to end: ``run_scene`` wall time and success.

    python benchmarks/low_level_planners.py [--out DIR] [--repeats 3] [--planners sto trajopt rrt]
        [--initialisers hlp line]

Runs ``python -m hlp_drake.run_scene --low-level P --planner I --json ...`` as a user does (a fresh
process: imports, model loading, planning, execution in the reference world and the grasp), the
planners interleaved repeat by repeat so they share the machine's load. Reports per planner and
initialiser the median and each wall time, the children's CPU time, the success and the low-level
planner the JSON names. The issue's target: ``trajopt`` and ``rrt`` under 10 s of wall time each on
2 cores. Writes ``DIR/low_level_planners.json`` and ``DIR/low_level_planners.png``.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from hlp_drake.commands.parsing import run_cli
from hlp_drake.files.atomic import check_folder, write_text_atomic
from hlp_drake.files.plotting import new_figure, save_png

OUTPUTS = ("low_level_planners.json", "low_level_planners.png")


def _run(planner: str, initial: str, folder: Path) -> dict:
    """One ``run_scene`` in a fresh process: its wall and CPU seconds and what its JSON says."""
    out = folder / f"{planner}-{initial}.json"
    argv = [sys.executable, "-m", "hlp_drake.run_scene", "--low-level", planner, "--planner", initial]
    cpu = resource.getrusage(resource.RUSAGE_CHILDREN)
    started = time.perf_counter()
    done = subprocess.run([*argv, "--quiet", "--json", str(out)], capture_output=True, text=True, check=False)
    wall = time.perf_counter() - started
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    report = json.loads(out.read_text()) if out.exists() else {}
    return {
        "wall_s": wall,
        "cpu_s": after.ru_utime + after.ru_stime - cpu.ru_utime - cpu.ru_stime,
        "exit": done.returncode,
        "success": bool(report.get("success")),
        "low_level": report.get("low_level"),
        "optimise_s": report.get("timings", {}).get("optimise_s"),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("benchmark-results"))
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--planners", nargs="+", default=["sto", "trajopt", "rrt"])
    parser.add_argument("--initialisers", nargs="+", default=["hlp", "line"])
    args = parser.parse_args()
    check_folder(args.out, *OUTPUTS).mkdir(exist_ok=True)
    runs: dict[str, list[dict]] = {}
    with tempfile.TemporaryDirectory() as scratch:
        for repeat in range(args.repeats):
            for planner in args.planners:
                for initial in args.initialisers:
                    run = _run(planner, initial, Path(scratch))
                    runs.setdefault(f"{initial}+{planner}", []).append(run)
                    print(
                        f"repeat {repeat + 1}: {initial}+{planner} {run['wall_s']:.1f} s, success {run['success']}"
                    )
    rows = {
        name: {
            "median_wall_s": statistics.median(r["wall_s"] for r in got),
            "median_cpu_s": statistics.median(r["cpu_s"] for r in got),
            "success": sum(r["success"] for r in got),
            "runs": got,
        }
        for name, got in runs.items()
    }
    report = {
        "machine": {
            "cpus": os.cpu_count(),
            "processor": platform.processor(),
            "python": platform.python_version(),
        },
        "load_before": os.getloadavg(),
        "repeats": args.repeats,
        "conditions": rows,
    }
    write_text_atomic(args.out / OUTPUTS[0], json.dumps(report, indent=1))
    figure, axes = new_figure(7.0, 3.5)
    names = list(rows)
    axes.bar(names, [rows[n]["median_wall_s"] for n in names], color="tab:blue")
    axes.axhline(10.0, color="tab:red", linestyle="--", label="10 s target (trajopt, rrt)")
    axes.set_ylabel("run_scene wall time, median (s)")
    axes.tick_params(axis="x", rotation=30)
    axes.legend()
    save_png(figure, args.out / OUTPUTS[1])
    for name in names:
        print(
            f"{name}: median {rows[name]['median_wall_s']:.1f} s wall, {rows[name]['success']}/{args.repeats} success"
        )
    print(f"wrote {args.out / OUTPUTS[0]}, {args.out / OUTPUTS[1]}")


if __name__ == "__main__":
    raise SystemExit(run_cli(lambda _argv: main() or 0))  # bad paths: one line, exit 2
