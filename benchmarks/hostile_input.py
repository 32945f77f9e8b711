"""Time and memory of refused hostile inputs up to 10 MB, and the time to validate 10,000 objects.

    python benchmarks/hostile_input.py [--json OUT.json]

Each refused input is loaded in a fresh process (the API a command uses: ``load_scene``,
``load_scenario``, ``DecisionModels.load``, the dataset's track parser); the process's peak RSS
before and after the call and the call's wall time are reported (targets: < 200 MB, < 2 s). Then a
valid 10,000-object scene: ``scene_problems`` on the Scene, and ``load_scene`` of it as YAML and
JSON (medians of 3). Figures: docs/method.md#hostile-input.
"""

from __future__ import annotations

import argparse
import hashlib
import io
import json
import os
import platform
import resource
import statistics
import subprocess
import sys
import tempfile
import time
import zipfile
from pathlib import Path

import numpy as np
import yaml

from hlp_drake.commands.parsing import run_cli
from hlp_drake.files.atomic import check_writable, write_text_atomic

MB = 10**6
_OBSTACLE = "- {{name: o{i}, shape: box, x: {x:.3f}, y: {y:.3f}, yaw: 0.0, size: [0.02, 0.02, 0.1]}}\n"
_HEAD = (
    "name: big\ntable: {length: 4.5, width: 4.0, height: 0.7}\nstart: [0.05, 0.0]\n"
    "target: {name: T, shape: cylinder, x: 4.3, y: 1.9, size: [0.05, 0.05, 0.1]}\nobstacles:\n"
)


def _grid_scene(n: int, *, same: bool = False) -> str:
    """A YAML scene of ``n`` boxes on a grid (all in one place with ``same``)."""
    lines = [
        _OBSTACLE.format(
            i=i, x=1.0 if same else 0.1 + (i % 100) * 0.04, y=0.0 if same else -1.9 + (i // 100) * 0.038
        )
        for i in range(n)
    ]
    return _HEAD + "".join(lines)


def _scene_of_size(size: int) -> str:
    """A YAML scene of about ``size`` bytes (more obstacles than allowed)."""
    per = len(_OBSTACLE.format(i=10**5, x=1.0, y=1.0))
    return _grid_scene(size // per)


def _npz_with_huge_header(size: int) -> bytes:
    """The bundled ``models.npz`` with ``arm.train`` replaced by a header declaring 10^12 elements
    followed by ``size`` random bytes."""
    from hlp_drake.learners.bundled import BUNDLED_DIRECTORY

    buffer = io.BytesIO()
    with (
        zipfile.ZipFile(BUNDLED_DIRECTORY / "models.npz") as bundled,
        zipfile.ZipFile(buffer, "w") as archive,
    ):
        for info in bundled.infolist():
            if info.filename != "arm.train.npy":
                archive.writestr(info, bundled.read(info))
        member = io.BytesIO()
        np.lib.format.write_array_header_1_0(
            member, {"descr": "<f8", "fortran_order": False, "shape": (10**6, 10**6)}
        )
        member.write(os.urandom(size))
        archive.writestr("arm.train.npy", member.getvalue())
    return buffer.getvalue()


def _cases(folder: Path) -> dict[str, tuple[str, Path]]:
    """name -> (loader, file) of every refused input."""
    files: dict[str, tuple[str, bytes | str]] = {
        "scene 10 MB YAML (over the size limit)": ("scene", _scene_of_size(10 * MB)),
        "scene 7.9 MB YAML, ~80k obstacles (value limit)": ("scene", _scene_of_size(int(7.9 * MB))),
        "scene 7.9 MB JSON, ~80k obstacles (value limit)": ("scene_json", None),
        "scene 10,000 identical obstacles (1 MB, overlaps)": ("scene", _grid_scene(10_000, same=True)),
        "scene 7.9 MB of '[' (nesting)": ("scene", "start: " + "[" * int(7.9 * MB)),
        "scene 7.9 MB JSON of '[' (nesting)": ("scene_json", "[" * int(7.9 * MB)),
        "scene billion laughs (aliases)": (
            "scene",
            "a: &a [x, x, x, x, x, x, x, x, x]\n"
            + "".join(f"{c}: &{c} [{', '.join([f'*{p}'] * 9)}]\n" for p, c in zip("abcdefgh", "bcdefghi")),
        ),
        "scene 7.9 MB one number (digits)": ("scene", "table: {length: " + "9" * int(7.9 * MB) + "}\n"),
        "scene 7.9 MB one name (a long text)": ("scene", "name: " + "a" * int(7.9 * MB) + "\n"),
        "scenario 7.9 MB YAML, ~80k obstacles": (
            "scenario",
            "scene:\n" + "".join("  " + line + "\n" for line in _scene_of_size(int(7.8 * MB)).splitlines()),
        ),
        "models.npz 10 MB, header of 10^12 elements": ("models", _npz_with_huge_header(10 * MB)),
        "movement CSV 10 MB, NaN in its last row": ("track", None),
    }
    scene = yaml.safe_load(_scene_of_size(int(5.2 * MB)))
    files["scene 7.9 MB JSON, ~80k obstacles (value limit)"] = ("scene_json", json.dumps(scene))
    rows = "".join(
        f"{100 + i / 90:.4f},0.0148,0.7542,-0.2413,312.9742,353.1794,346.7536\n" for i in range(10 * MB // 60)
    )
    files["movement CSV 10 MB, NaN in its last row"] = (
        "track",
        "time,pos_x,pos_y,pos_z,rot_x,rot_y,rot_z\n" + rows + "999.0,NaN,0,0,0,0,0\n",
    )
    cases = {}
    for k, (name, (loader, content)) in enumerate(files.items()):
        suffix = {
            "scene": ".yaml",
            "scene_json": ".json",
            "scenario": ".yaml",
            "models": ".npz",
            "track": ".csv",
        }
        path = folder / f"case{k}{suffix[loader]}"
        (path.write_bytes if isinstance(content, bytes) else path.write_text)(content)
        cases[name] = (loader, path)
    return cases


def _peak_rss_mb() -> float:
    """This process's peak resident set, MB (``VmHWM``: unlike ``ru_maxrss``, not inherited across exec)."""
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmHWM:"):
            return int(line.split()[1]) / 1024
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def _child(loader: str, path: Path) -> None:
    """Load ``path`` with ``loader`` in this process; print peak RSS (MB) before/after and the time."""
    from hlp_drake.errors import HlpError
    from hlp_drake.scene.io import load_scene

    call = {"scene": load_scene, "scene_json": load_scene}.get(loader)
    if loader == "scenario":
        from hlp_drake.systems.scenario import load_scenario

        call = load_scenario
    elif loader == "models":
        from hlp_drake.learners.bundled import BUNDLED_DIRECTORY
        from hlp_drake.learners.models import DecisionModels

        folder = Path(tempfile.mkdtemp())
        (folder / "models.npz").write_bytes(path.read_bytes())
        meta = json.loads((BUNDLED_DIRECTORY / "models.json").read_text())
        meta["sha256"] = hashlib.sha256((folder / "models.npz").read_bytes()).hexdigest()  # a consistent edit
        (folder / "models.json").write_text(json.dumps(meta))
        path, call = folder, DecisionModels.load
    elif loader == "track":
        from hlp_drake.dataset.parse import parse_movement

        def call(p):
            return parse_movement(Path(p).read_bytes(), "HandTracker")

    before = _peak_rss_mb()
    started = time.perf_counter()
    try:
        call(path)
        outcome = "accepted"
    except (HlpError, ValueError) as error:
        outcome = str(error).splitlines()[0][:120]
    seconds = time.perf_counter() - started
    after = _peak_rss_mb()
    print(json.dumps({"seconds": seconds, "rss_before_mb": before, "rss_peak_mb": after, "outcome": outcome}))


def _valid_10000() -> dict[str, float]:
    from hlp_drake.scene.io import load_scene, scene_to_dict
    from hlp_drake.scene.validation import scene_problems

    with tempfile.TemporaryDirectory() as folder:
        text = _grid_scene(10_000)
        yaml_path, json_path = Path(folder) / "s.yaml", Path(folder) / "s.json"
        yaml_path.write_text(text)
        scene = load_scene(yaml_path)
        json_path.write_text(json.dumps(scene_to_dict(scene)))
        times: dict[str, list[float]] = {"scene_problems": [], "load_scene YAML": [], "load_scene JSON": []}
        for _ in range(3):
            for name, call in (
                ("scene_problems", lambda: scene_problems(scene)),
                ("load_scene YAML", lambda: load_scene(yaml_path)),
                ("load_scene JSON", lambda: load_scene(json_path)),
            ):
                started = time.perf_counter()
                result = call()
                times[name].append(time.perf_counter() - started)
                assert result == [] or len(getattr(result, "obstacles", ())) == 10_000
        return {name: statistics.median(t) for name, t in times.items()}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--json", help="write the figures here")
    parser.add_argument("--child", nargs=2, help=argparse.SUPPRESS)
    args = parser.parse_args()
    check_writable(args.json)
    if args.child:
        _child(args.child[0], Path(args.child[1]))
        return
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        for name, (loader, path) in _cases(Path(folder)).items():
            done = subprocess.run(
                [sys.executable, __file__, "--child", loader, str(path)],
                capture_output=True,
                text=True,
                check=True,
            )
            row = {"input": name, "bytes": path.stat().st_size, **json.loads(done.stdout.splitlines()[-1])}
            rows.append(row)
            print(
                f"{name:<50} {row['bytes'] / MB:5.1f} MB {row['seconds']:6.2f} s  peak RSS {row['rss_peak_mb']:6.0f} MB "
                f"(+{row['rss_peak_mb'] - row['rss_before_mb']:4.0f})  {row['outcome'][:70]}",
                flush=True,
            )
    valid = _valid_10000()
    for name, seconds in valid.items():
        print(f"10,000 valid objects: {name} {seconds:.2f} s (median of 3)")
    if args.json:
        meta = {
            "machine": f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores",
            "python": platform.python_version(),
        }
        write_text_atomic(
            args.json, json.dumps({"meta": meta, "refused": rows, "valid_10000": valid}, indent=2) + "\n"
        )


if __name__ == "__main__":
    raise SystemExit(run_cli(lambda _argv: main() or 0))  # bad paths: one line, exit 2
