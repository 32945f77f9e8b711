"""What the MeshCat recording and the live server show of a run: the view, the highlighted pushes, the heading."""

from __future__ import annotations

import json
import os

import numpy as np
import pytest
from conftest import run_module
from meshcat_support import _websocket_frames, animation_tracks

from hlp_drake.scene.generators import generate_scene
from hlp_drake.systems.execution.meshcat_view import camera_pose


@pytest.mark.parametrize(
    "scene",
    [generate_scene("vr", 1), generate_scene("gen1", 3), generate_scene("gen2", 4, 9)],
    ids=lambda scene: scene.name,
)
def test_the_view_looks_at_the_table_from_the_persons_side_and_fills_the_frame(scene):
    """MeshCat's camera (a 75 degree vertical field of view; a 1280 x 800 window): above the person's
    side (x < 0), 55 degrees up, to the left (the arm reaches from the right); every corner of the
    table top in view, the table over nearly half of the frame's width (0.47-0.6 on Gen I and II)."""
    eye, target = camera_pose(scene)
    table = scene.table
    view = target - eye
    assert eye[0] < 0.0 < target[0] < table.length and eye[1] > 0.0
    assert np.degrees(np.arcsin(-view[2] / np.linalg.norm(view))) == pytest.approx(55.0)
    forward = view / np.linalg.norm(view)
    right = np.cross(forward, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    focal = 1.0 / np.tan(np.radians(75.0) / 2.0)
    corners = [(x, y, table.height) for x in (0.0, table.length) for y in (-table.width / 2, table.width / 2)]
    seen = np.array(
        [
            (focal * (d @ right) / (d @ forward) / 1.6, focal * (d @ up) / (d @ forward))
            for d in np.array(corners) - eye
        ]
    )
    assert np.all(np.abs(seen) < 1.0), seen  # normalised image coordinates
    assert np.ptp(seen[:, 0]) / 2.0 > 0.45


def test_the_recording_highlights_each_pushed_obstacle_while_it_is_pushed_and_says_what_ran(tmp_path):
    """The default scene's two pushes: each obstacle's highlight is hidden at the start, shown from
    about when the robot starts pushing it (it has barely moved yet) to its release (it has moved
    several centimetres meanwhile), then hidden; the heading names the scene and the verdict."""
    out, html = tmp_path / "run.json", tmp_path / "run.html"
    args = ("--workers", "1", "--quiet", "--json", str(out), "--html", str(html))
    result = run_module("hlp_drake.run_scene", *args, env={"DRAKE_ALLOW_NETWORK": "meshcat"})
    assert result.returncode == 0, result.stderr
    report = json.loads(out.read_text())
    moves = [k["element"] for k in report["plan"]["keypoints"] if k["action"] == "move"]
    page = html.read_text()
    tracks = animation_tracks(page)
    highlighted = {
        path.split("/")[3]: t[".visible"] for path, t in tracks.items() if path.endswith("/pushed")
    }
    assert sorted(highlighted) == sorted(moves) and len(moves) == 2
    for name, keys in highlighted.items():
        assert [shown for _, shown in keys] == [False, True, False], (name, keys)
        start, end = keys[1][0], keys[2][0]
        position = np.array([value for _, value in tracks[f"/drake/visualizer/{name}/{name}"][".position"]])
        before = np.linalg.norm(position[start, :2] - position[0, :2])
        during = np.linalg.norm(position[end, :2] - position[start, :2])
        assert during > 0.05 and before < 0.25 * during, (name, before, during)
    title = (
        "scene default (gen1 seed 3), human-like planner with the sto low-level planner on the true scene: "
    )
    title += "reach success in the reference world (the model: accepted), grasp "
    assert title in page and 'id="hlp-clock"' in page


def test_run_scene_meshcat_serves_the_run_live(tmp_path):
    """``--meshcat``: the URL is printed, the viewer page is served, a browser's WebSocket receives
    the robot, the objects, the plans' path lines and the robot plan's keypoints, and Ctrl-C ends
    the run cleanly."""
    import signal
    import subprocess
    import sys
    import urllib.request

    out = tmp_path / "run.json"
    process = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "hlp_drake.run_scene",
            "--meshcat",
            "--world",
            "model",
            "--workers",
            "1",
            "--json",
            str(out),
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env={**os.environ, "DRAKE_ALLOW_NETWORK": "meshcat"},
    )
    try:
        lines = []
        for line in process.stdout:
            lines.append(line)
            if "keeps serving" in line:
                break
        url = next(
            (line.split("MeshCat: ")[1].strip() for line in lines if line.startswith("MeshCat: ")), None
        )
        if url is None:
            pytest.skip(
                f"MeshCat did not start here: {process.stderr.read() if process.poll() is not None else lines}"
            )
        page = urllib.request.urlopen(url, timeout=10).read()
        assert b"<title>Drake MeshCat</title>" in page
        scene_tree = _websocket_frames(url.replace("http://", "ws://"), seconds=3.0)
        for path in (
            b"/drake/robot_plan/00_start",
            b"/drake/robot_plan/path",
            b"/drake/plan/path",
            b"mobile_ur5",
            b"Target",
            b"table",
        ):
            assert path in scene_tree, path
        process.send_signal(signal.SIGINT)
        assert process.wait(timeout=30) == 0
    finally:
        if process.poll() is None:
            process.kill()
    assert json.loads(out.read_text())["success"] is True
