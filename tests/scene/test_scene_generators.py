"""Seeded generators: determinism, validity and the structure each kind promises."""

from __future__ import annotations

import math
from collections import Counter

import numpy as np
import pytest

from hlp_drake.errors import SceneError
from hlp_drake.scene import KINDS, find_rows, generate_scene, scene_problems
from hlp_drake.scene.generators import VR_OBSTACLE_WIDTHS


@pytest.mark.parametrize("kind", KINDS)
def test_same_seed_same_scene_other_seed_other_scene(kind):
    assert generate_scene(kind, 5) == generate_scene(kind, 5)
    assert generate_scene(kind, 5).obstacles != generate_scene(kind, 6).obstacles


@pytest.mark.parametrize("kind", KINDS)
def test_many_seeds_are_valid(kind):
    for seed in range(60):
        assert scene_problems(generate_scene(kind, seed)) == []


def test_vr_structure():
    sizes = Counter()
    for seed in range(40):
        scene = generate_scene("vr", seed)
        rows = find_rows(scene)
        assert [r.x for r in rows] == pytest.approx([0.245, 0.405])
        assert scene.start == (0.1, 0.0) and scene.target.position == (0.525, 0.0)
        for row in rows:
            widths = sorted(scene.obstacle(n).size[1] for n in row.members)
            assert widths == pytest.approx(sorted(VR_OBSTACLE_WIDTHS.values()))
            # free intervals (edges and between obstacles) are >= 5 mm on a 5 mm grid
            edges = [scene.table.width / 2]
            for name in row.members:  # left to right
                o = scene.obstacle(name)
                edges += [o.y + o.size[1] / 2, o.y - o.size[1] / 2]
            edges.append(-scene.table.width / 2)
            gaps = np.array(edges[0::2]) - np.array(edges[1::2])
            assert gaps.min() >= 0.005 - 1e-9
            assert np.allclose(np.round(gaps / 0.005) * 0.005, gaps, atol=1e-6)
            sizes[tuple(scene.obstacle(n).size[1] for n in row.members)] += 1
    assert len(sizes) == 6  # every left-to-right order of short/medium/long occurs


def test_gen1_varies_dimensions_but_keeps_two_rows():
    scenes = [generate_scene("gen1", s) for s in range(30)]
    assert all(len(find_rows(s)) == 2 and len(s.obstacles) == 6 for s in scenes)
    assert len({s.table.width for s in scenes}) == 30
    assert len({s.obstacles[0].size for s in scenes}) == 30
    for s in scenes:
        assert s.start[1] == 0.0 and s.target.y == 0.0
        assert 0.9 <= s.table.width <= 1.3  # robot-sized, not the 0.74 m VR table
        assert s.target.size[0] <= 0.07  # graspable with an 85 mm stroke


@pytest.mark.parametrize("objects", [5, 7, 9])
def test_gen2_structure(objects):
    shapes = Counter()
    for seed in range(20):
        s = generate_scene("gen2", seed, objects)
        assert len(s.obstacles) == objects
        assert s.start[0] == 0.0  # on the front edge
        assert abs(s.target.y - s.start[1]) >= 0.1 * s.table.width  # not aligned with the start
        assert abs(s.start_yaw) <= math.pi / 4
        shapes.update(o.shape for o in s.obstacles)
    assert set(shapes) == {"box", "cylinder"}


def test_unstructured_on_a_1cm_grid():
    s = generate_scene("unstructured", 3, 8)
    assert len(s.obstacles) == 8
    assert all(abs(o.x * 100 - round(o.x * 100)) < 1e-6 for o in s.obstacles)


def test_bad_requests():
    with pytest.raises(SceneError, match="unknown scene kind"):
        generate_scene("maze", 1)
    with pytest.raises(SceneError, match="always have 6 obstacles"):
        generate_scene("vr", 1, objects=4)
    with pytest.raises(SceneError, match="could not place"):
        generate_scene("gen2", 1, objects=100)
    with pytest.raises(SceneError, match="must be an integer of at most 100, got 400"):
        generate_scene("gen2", 1, objects=400)  # refused before any placement is tried
    with pytest.raises(SceneError, match="at least 1 object"):
        generate_scene("gen2", 1, objects=0)
