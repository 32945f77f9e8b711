"""How well and how fast ``ScenePerception`` sees Generalization II scenes through the default camera.

    python benchmarks/perception.py [--objects 9 15] [--scenes 100 30] [--seed 0] [--width 640]
        [--height 480] [--roll DEG] [--json OUT] [--csv OUT] [--png OUT]

Per object count K (with --scenes N for it: scenes gen2-K-seed .. seed+N-1), every scene's world is
built with the scenario's default camera (640 x 480, 1.6 m above the table, turned 3 degrees about
its optical axis, its seeded depth noise and dropout; --roll DEG turns it by DEG from the table's
axes instead, 0 for edges along the pixel grid) and one frame rendered
and perceived. Reported per count: position, size and yaw
(boxes) error, median and p95, over the matched objects; the share of scenes with every object
found (none missed, none invented, perception ok); the share of the human-like plan's row decisions
on the perceived scene equal to those on the true scene, beside the same share for the true scene
changed by seeded noise of about the perception's errors (``JITTER``: the planner's own sensitivity); the perception time per frame (median,
p95) with the rendering timed separately. The issue's targets are printed beside. Times depend on
the machine's load: the load average is recorded.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd
from tqdm import tqdm

from hlp_drake.commands.parsing import run_cli
from hlp_drake.files.atomic import check_writable, write_text_atomic
from hlp_drake.files.plotting import new_figure, save_png
from hlp_drake.learners.bundled import default_models
from hlp_drake.planner import plan
from hlp_drake.scene.generators import generate_scene
from hlp_drake.scene.model import Scene, SceneObject
from hlp_drake.systems.perception.accuracy import match_objects, perception_record, same_decisions
from hlp_drake.systems.perception.cameras import CameraConfig, PerceptionConfig
from hlp_drake.systems.perception.system import ScenePerception
from hlp_drake.systems.scenario import Scenario
from hlp_drake.systems.world.world import make_world_diagram

TARGETS = {
    "position_median_mm": 5.0,
    "position_p95_mm": 15.0,
    "size_median_mm": 5.0,
    "yaw_median_deg": 5.0,
    "all_found": {9: 0.99, 15: 0.97},
    "same_decisions": 0.95,
    "perception_median_ms": 100.0,
}
JITTER = {"position_m": 0.0005, "size_m": 0.001, "yaw_rad": 0.002, "table_m": 0.001}
"""The decisions' control: the true scene with noise of about the perception's errors (standard
deviations per axis)."""


def jitter(scene: Scene, seed: int) -> Scene:
    """``scene`` changed by seeded Gaussian noise of ``JITTER``'s sizes: every object's x, y, size
    and (boxes) yaw, and the table's length and width."""
    rng = np.random.default_rng(seed)

    def changed(o: SceneObject) -> SceneObject:
        dx, dy = rng.normal(0.0, JITTER["position_m"], 2)
        ds = rng.normal(0.0, JITTER["size_m"], 3)
        size = (
            (o.size[0] + ds[0], o.size[0] + ds[0], o.size[2] + ds[2])
            if o.shape == "cylinder"
            else tuple(np.add(o.size, ds))
        )
        yaw = o.yaw + (rng.normal(0.0, JITTER["yaw_rad"]) if o.shape == "box" else 0.0)
        return replace(o, x=o.x + dx, y=o.y + dy, size=size, yaw=yaw)

    dl, dw = rng.normal(0.0, JITTER["table_m"], 2)
    table = replace(scene.table, length=scene.table.length + dl, width=scene.table.width + dw)
    target, *obstacles = (changed(o) for o in scene.objects)
    return replace(scene, table=table, target=target, obstacles=tuple(obstacles))


def perceive_scene(kind_seed: tuple[int, int], camera: CameraConfig, models) -> tuple[dict, list[dict]]:
    """One scene's frame: its summary row and its objects' error rows."""
    objects, seed = kind_seed
    scene = generate_scene("gen2", seed, objects)
    scenario = Scenario(scene=scene, perception=PerceptionConfig(source="camera", cameras=(camera,)))
    world = make_world_diagram(scenario)
    context = world.CreateDefaultContext()
    started = time.perf_counter()
    frame = {
        p: world.GetOutputPort(f"{camera.name}.{p}").Eval(context) for p in ("depth_image", "label_image")
    }
    render_s = time.perf_counter() - started
    block = ScenePerception(template=scenario.scene, config=scenario.perception)
    block_context = block.CreateDefaultContext()
    for port, value in frame.items():
        block.GetInputPort(f"{camera.name}.{port}").FixValue(block_context, value)
    pose = world.GetOutputPort(f"{camera.name}.camera_pose").Eval(context)
    block.GetInputPort(f"{camera.name}.camera_pose").FixValue(block_context, pose)
    started = time.perf_counter()
    perception = block.get_perception_output_port().Eval(block_context)
    block_s = time.perf_counter() - started
    record = perception_record(scene, perception)
    same, rows = 0, 0
    true_plan = plan(scene, models)
    if perception.ok:
        same, rows = same_decisions(
            true_plan, plan(perception.scene, models), match_objects(scene, perception.scene)
        )
    jittered = jitter(scene, seed)
    jitter_same, jitter_rows = same_decisions(
        true_plan, plan(jittered, models), {o.name: o.name for o in scene.objects}
    )
    row = {
        "scene": scene.name,
        "objects": objects,
        "ok": perception.ok,
        "reason": perception.reason,
        "missed": len(record["missed"]),
        "invented": len(record["invented"]),
        "render_ms": 1e3 * render_s,
        "perception_ms": 1e3 * perception.perception_s,
        "block_ms": 1e3 * block_s,
        "same_rows": same,
        "rows": rows,
        "jitter_same_rows": jitter_same,
        "jitter_rows": jitter_rows,
    }
    errors = [{"scene": scene.name, "objects": objects, **o} for o in record["objects"]]
    return row, errors


def summarise(scenes: pd.DataFrame, errors: pd.DataFrame) -> dict:
    """Per object count, the figures of the module's docstring."""
    out = {}
    for count, group in scenes.groupby("objects"):
        e = errors[errors["objects"] == count]
        yaw = np.degrees(e["yaw_error_rad"].dropna().astype(float))
        found = group["ok"] & (group["missed"] == 0) & (group["invented"] == 0)
        out[int(count)] = {
            "scenes": len(group),
            "objects_matched": len(e),
            "position_median_mm": 1e3 * float(e["position_error_m"].median()),
            "position_p95_mm": 1e3 * float(e["position_error_m"].quantile(0.95)),
            "size_median_mm": 1e3 * float(e["size_error_m"].median()),
            "size_p95_mm": 1e3 * float(e["size_error_m"].quantile(0.95)),
            "yaw_median_deg": float(yaw.median()),
            "yaw_p95_deg": float(yaw.quantile(0.95)),
            "all_found": float(found.mean()),
            "failures": sorted({r for r in group["reason"].dropna()}),
            "same_decisions": float(group["same_rows"].sum() / max(group["rows"].sum(), 1)),
            "same_decisions_jittered_truth": float(
                group["jitter_same_rows"].sum() / max(group["jitter_rows"].sum(), 1)
            ),
            "perception_median_ms": float(group["perception_ms"].median()),
            "perception_p95_ms": float(group["perception_ms"].quantile(0.95)),
            "render_median_ms": float(group["render_ms"].median()),
        }
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--objects", type=int, nargs="+", default=[9, 15])
    parser.add_argument("--scenes", type=int, nargs="+", default=[100, 30], help="one per --objects")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--width", type=int, default=640)
    parser.add_argument("--height", type=int, default=480)
    parser.add_argument(
        "--roll", type=float, help="the camera turned about its axis, degrees (default: the default camera's)"
    )
    parser.add_argument("--json", type=Path)
    parser.add_argument("--csv", type=Path, help="the objects' errors, one row each")
    parser.add_argument("--png", type=Path)
    args = parser.parse_args()
    check_writable(args.json, args.csv, args.png)
    if len(args.scenes) != len(args.objects):
        parser.error("give one --scenes per --objects")
    camera = CameraConfig(width=args.width, height=args.height)
    if args.roll is not None:
        roll = math.radians(args.roll)
        camera = replace(camera, up=(math.cos(roll), math.sin(roll), 0.0))
    models = default_models()
    todo = [(k, args.seed + i) for k, n in zip(args.objects, args.scenes) for i in range(n)]
    load = os.getloadavg()
    rows, errors = [], []
    for item in tqdm(todo, unit="scene", desc="perceive"):
        row, objects = perceive_scene(item, camera, models)
        rows.append(row)
        errors += objects
    scenes, errors = pd.DataFrame(rows), pd.DataFrame(errors)
    summary = summarise(scenes, errors)
    report = {
        "camera": f"{args.width} x {args.height}",
        "camera_roll_deg": math.degrees(math.atan2(camera.up[1], camera.up[0])),
        "load_before": load,
        "load_after": os.getloadavg(),
        "targets": {k: v for k, v in TARGETS.items() if k != "all_found"},
        "by_objects": summary,
    }
    print(json.dumps(report, indent=2))
    for count, figures in summary.items():
        target = TARGETS["all_found"].get(count)
        print(
            f"{count} objects: every object found in {figures['all_found']:.0%} of scenes"
            + (f" (target >= {target:.0%})" if target else "")
        )
    if args.json:
        write_text_atomic(args.json, json.dumps(report, indent=2) + "\n")
    if args.csv:
        write_text_atomic(args.csv, errors.to_csv(index=False))
    if args.png:
        figure, axes = new_figure(7.0, 4.0)
        for count in summary:
            e = errors[errors["objects"] == count]["position_error_m"] * 1e3
            axes.hist(e, bins=40, histtype="step", label=f"{count} objects")
        axes.axvline(TARGETS["position_median_mm"], linestyle="--", color="grey")
        axes.set_xlabel("position error, mm")
        axes.set_ylabel("objects")
        axes.legend()
        save_png(figure, args.png)
    if not math.isfinite(sum(f["position_median_mm"] for f in summary.values())):
        raise SystemExit("no object was matched")


if __name__ == "__main__":
    raise SystemExit(run_cli(lambda _argv: main() or 0))  # bad paths: one line, exit 2
