"""What the MeshCat recording shows beyond the plans: each pushed object highlighted while it is pushed,
the legend (the scene's colours, the push highlight, what the perception view draws) and the heading
with the recording's clock."""

from __future__ import annotations

import html
from itertools import pairwise

import numpy as np
import pytest
from meshcat_support import animation_tracks, messages

from hlp_drake.planner.plan import HighLevelPlan, PlanKeypoint
from hlp_drake.scene.generators import generate_scene
from hlp_drake.systems.execution.meshcat_view import (
    PASSED_WITHIN,
    PUSHED_COLOUR,
    PUSHED_MARGIN,
    Push,
    align_keypoints,
    highlight_pushes,
    legend_html,
    legend_rows,
    push_times,
    with_legend,
)

TABLE, TCP = 0.75, 0.81  # table top and tcp keypoint heights, m


def test_keypoints_are_passed_in_order_even_where_the_path_comes_back():
    """The tcp goes out to p, back to q and out to p again: the keypoints p, q, p are its three
    turns, not the first time it came near each place."""
    out = np.linspace(0.0, 1.0, 11)
    x = np.concatenate([out, out[::-1][1:], out[1:]])  # 0 -> 1 -> 0 -> 1, 31 samples
    path = np.column_stack([x, np.zeros_like(x), np.zeros_like(x)])
    p, q = [1.0, 0.0, 0.0], [0.0, 0.0, 0.0]
    assert list(align_keypoints(np.array([q, p, q, p]), path)) == [0, 10, 20, 30]
    assert list(align_keypoints(np.array([p, q]), path)) == [10, 20]
    assert list(align_keypoints(np.zeros((0, 3)), path)) == [] and list(align_keypoints([p], [])) == []


def robot_plan(*keypoints: tuple[str, float, float, str | None]) -> HighLevelPlan:
    return HighLevelPlan(
        "test", tuple(PlanKeypoint(action, (x, y), element=element) for action, x, y, element in keypoints)
    )


PLAN = robot_plan(
    ("start", 0.0, 0.0, None),
    ("move", 0.2, 0.1, "box"),
    ("release", 0.2, -0.1, "box"),
    ("move", 0.4, 0.0, "seen_can"),
    ("release", 0.4, 0.2, "seen_can"),
    ("target", 0.6, 0.0, "Target"),
)


def tcp_through(points: list[tuple[float, float]], samples: int = 20) -> tuple[np.ndarray, np.ndarray]:
    """(times, tcp positions): the tcp at keypoint height along straight legs through ``points``, one
    leg a second."""
    legs = [
        np.column_stack([np.linspace(a[0], b[0], samples), np.linspace(a[1], b[1], samples)])
        for a, b in pairwise(points)
    ]
    xy = np.vstack([legs[0]] + [leg[1:] for leg in legs[1:]])
    times = np.linspace(0.0, len(legs), len(xy))
    return times, np.column_stack([xy, np.full(len(xy), TCP)])


def test_each_push_lasts_from_its_move_keypoint_to_its_release_as_the_tcp_passed_them():
    times, tcp = tcp_through([(0.0, 0.0), (0.2, 0.1), (0.2, -0.1), (0.4, 0.0), (0.4, 0.2), (0.6, 0.0)])
    pushes = push_times(PLAN, times, tcp, table_height=TABLE, keypoint_height=TCP)
    assert pushes == [Push("box", 1.0, 2.0), Push("seen_can", 3.0, 4.0)]
    # Planned on a perceived scene: the true names; an object matched to none is not highlighted.
    named = push_times(PLAN, times, tcp, table_height=TABLE, keypoint_height=TCP, names={"box": "b1"})
    assert named == [Push("b1", 1.0, 2.0)]
    # A push whose start the tcp never came near (another plan ran) is left out.
    times, tcp = tcp_through([(0.0, 0.0), (0.0, -0.1), (0.2, -0.1), (0.6, 0.0)])
    assert np.min(np.linalg.norm(tcp[:, :2] - [0.2, 0.1], axis=1)) > PASSED_WITHIN
    assert [p.element for p in push_times(PLAN, times, tcp, table_height=TABLE, keypoint_height=TCP)] == []


@pytest.fixture
def meshcat(monkeypatch):
    from pydrake.geometry import Meshcat, MeshcatParams

    monkeypatch.setenv("DRAKE_ALLOW_NETWORK", "meshcat")  # a local server only; still no remote packages
    try:
        return Meshcat(MeshcatParams(host="localhost"))
    except RuntimeError as error:
        pytest.skip(f"MeshCat cannot start here: {error}")


def test_a_pushed_object_is_highlighted_in_the_recording_only_while_it_is_pushed(meshcat):
    scene = generate_scene("gen1", 3)
    box, cylinder = scene.obstacles[0], scene.target  # a box and a cylinder
    fps = 32.0
    meshcat.StartRecording(frames_per_second=fps)
    pushes = [Push(box.name, 1.0, 2.5), Push(cylinder.name, 3.0, 4.0), Push(box.name, 5.0, 6.0)]
    highlight_pushes(meshcat, scene, [*pushes, Push("not_in_the_scene", 1.0, 2.0)])
    meshcat.StopRecording()
    meshcat.PublishRecording()
    page = meshcat.StaticHtml()
    tracks = animation_tracks(page)
    shown = {
        name: tracks[f"/drake/visualizer/{name}/{name}/pushed"][".visible"]
        for name in (box.name, cylinder.name)
    }
    assert shown[box.name] == [(0, False), (32, True), (80, False), (160, True), (192, False)]
    assert shown[cylinder.name] == [(0, False), (96, True), (128, False)]
    assert not any("not_in_the_scene" in path for path in tracks)
    # A shell just outside each object, in the highlight's colour, a child of its body's frame; hidden
    # when the recording is not playing.
    sent = messages(page)
    shells = {
        m["path"]: m["object"] for m in sent if m["type"] == "set_object" and m["path"].endswith("/pushed")
    }
    box_shell = shells[f"/drake/visualizer/{box.name}/{box.name}/pushed"]["geometries"][0]
    size = [box_shell[key] for key in ("width", "height", "depth")]
    assert size == pytest.approx([s + 2 * PUSHED_MARGIN for s in box.size])
    can_shell = shells[f"/drake/visualizer/{cylinder.name}/{cylinder.name}/pushed"]["geometries"][0]
    assert can_shell["radiusTop"] == pytest.approx(cylinder.size[0] / 2 + PUSHED_MARGIN)
    rgb = [255 * c for c in (PUSHED_COLOUR.r(), PUSHED_COLOUR.g(), PUSHED_COLOUR.b())]
    for shell in shells.values():  # three.js's 0xRRGGBB
        colour = shell["materials"][0]["color"]
        assert [colour >> 16, colour >> 8 & 0xFF, colour & 0xFF] == pytest.approx(rgb, abs=1)
    visible = {
        m["path"]: m["value"] for m in sent if m["type"] == "set_property" and m["property"] == "visible"
    }
    assert {visible[path] for path in shells} == {False}


def test_the_legend_names_the_scenes_colours_the_push_highlight_and_the_perception_view():
    rows = [text for _, text in legend_rows()]
    assert "the target and the obstacles, as simulated" in rows
    assert any(text.startswith("an obstacle while the robot pushes it") for text in rows)
    assert not any("depth camera" in text for text in rows)
    perceived = [text for _, text in legend_rows(perceived=True)]
    assert perceived[: len(rows)] == rows
    fitted, points = perceived[len(rows) :]
    assert fitted.startswith("perceived (translucent): the target and obstacles fitted to the depth camera")
    assert "where they were seen" in fitted
    assert points.startswith("the depth camera's points at the start: table, object")
    page = legend_html(perceived=True, title="scene <x> & y")
    assert html.escape("the depth camera's points") in page and "scene &lt;x&gt; &amp; y" in page


def test_the_recording_gets_a_heading_with_its_clock_and_the_legend_before_the_end_of_its_body():
    page = with_legend("<html><body><div id='meshcat-pane'></div></body></html>", title="scene default")
    assert page.endswith("</body></html>")
    for part in ('id="hlp-title"', "scene default", 'id="hlp-clock"', 'id="hlp-legend"'):
        assert part in page
    # The clock follows the animation MeshCat plays: set with each frame its animator updates.
    assert "viewer.animator" in page and "animator.update = function" in page
