"""``python -m hlp_drake.run_scene --perception camera`` end to end: planning on the perceived scene,
the JSON's ``perception`` record and the MeshCat recording of the point cloud and fitted objects."""

from __future__ import annotations

import json

from conftest import run_module
from test_run_scene import recorded

from hlp_drake.scene.generators import generate_scene


def test_run_scene_plans_on_the_perceived_scene_and_reports_its_errors(tmp_path):
    out, html = tmp_path / "run.json", tmp_path / "run.html"
    args = ("--kind", "vr", "--seed", "1", "--workers", "1", "--perception", "camera")
    network = {"DRAKE_ALLOW_NETWORK": "meshcat"}  # a recording needs a local MeshCat server (CI sets none)
    result = run_module(
        "hlp_drake.run_scene", *args, "--json", str(out), "--html", str(html), "--verbose", env=network
    )
    assert result.returncode in (0, 1) and "Traceback" not in result.stderr, result.stderr
    assert "INFO:drake:Meshcat listening for connections" in result.stderr  # shown with --verbose only
    assert "perceive: 7 objects, the target Target" in result.stdout
    report = json.loads(out.read_text())
    record = report["perception"]
    assert record["ok"] and record["reason"] is None
    assert record["missed"] == [] and record["invented"] == []
    true = generate_scene("vr", 1)
    assert sorted(o["name"] for o in record["objects"]) == sorted(o.name for o in true.objects)
    for error in record["objects"]:
        assert error["position_error_m"] < 0.005 and error["size_error_m"] < 0.005, error
        assert error["yaw_error_rad"] is None or error["yaw_error_rad"] < 0.05, error
    # The plan names the true objects the perceived ones were matched to, the perceived names beside;
    # the simulation moves the true ones.
    matched_to = {o["name"]: o["matched_to"] for o in record["perceived"]}
    assert set(matched_to.values()) == {o.name for o in true.objects}
    assert {e["perceived_as"]: e["name"] for e in record["objects"]} == matched_to
    named = [k for k in report["plan"]["keypoints"] if k["action"] not in ("start", "gap")]
    assert named and all(k["element"] == matched_to[k["perceived_as"]] for k in named)
    for k in named:
        if k["action"] == "move":
            seen = "" if k["element"] == k["perceived_as"] else f" (seen as {k['perceived_as']})"
            assert f"move {k['element']}{seen} {k['direction']}" in result.stdout
    assert set(report["objects_moved"]) <= {o.name for o in true.objects}
    assert report["perception_source"] == "camera" and "perception camera" in result.stdout
    assert report["timings"]["perceive_s"] > record["perception_s"] > 0
    page = html.read_text()
    # The legend says what the perception view draws: the fitted objects and the camera's points.
    assert "perceived (translucent): the target and obstacles fitted to the depth camera" in page
    assert "the depth camera&#x27;s points at the start" in page
    assert "human-like planner with the sto low-level planner on the depth camera&#x27;s view" in page
    commands = recorded(page)
    for path in (b"/drake/perception/points", b"/drake/perception/objects/Target", b"/drake/robot_plan/path"):
        assert path in commands, path


def test_run_scene_with_a_camera_that_sees_no_table_fails_with_the_reason(tmp_path):
    config, out = tmp_path / "sky.yaml", tmp_path / "run.json"
    config.write_text(
        "perception:\n  cameras: [{name: sky_camera, width: 160, height: 120, look_at: [0.0, 0.0, 3.0]}]\n"
    )
    args = ("--perception", "camera", "--config", str(config), "--workers", "1", "--json", str(out))
    result = run_module("hlp_drake.run_scene", *args)
    assert result.returncode == 1 and "Traceback" not in result.stderr
    reason = "perception failed: no table plane found (too few pixels with a depth)"
    assert f"verdict: reach failure in the reference world: {reason} (exit status 1)" in result.stdout
    report = json.loads(out.read_text())
    assert report["failure_reason"] == reason and not report["success"]
    assert report["perception"]["ok"] is False and "Target" in report["perception"]["missed"]
    assert report["rollouts"] == 0
