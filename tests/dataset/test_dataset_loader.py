"""The dataset loader on a tiny synthetic copy: formats, conversion, cache, and every bad input."""

from __future__ import annotations

import shutil
import threading

import numpy as np
import pytest
from conftest import run_module
from synthetic_dataset import hand_positions, write_archive, write_dataset

from hlp_drake.dataset import Dataset
from hlp_drake.dataset.cache import build_cache, cache_lock
from hlp_drake.errors import DatasetError


@pytest.fixture
def folder(tmp_path):
    return write_dataset(tmp_path / "dataset")


def load(path, tmp_path) -> Dataset:
    return Dataset(path, cache_dir=tmp_path / "cache", progress=False)


def test_records_categories_and_handedness(folder, tmp_path):
    ds = load(folder, tmp_path)
    assert ds.problems == []
    assert [(r.key, r.category, r.outcome, r.handedness) for r in ds.records] == [
        ("sub_01/T005", "practice", "Success", "right"),
        ("sub_01/T010", "structured", "Success", "right"),
        ("sub_01/T011", "structured", "ArmInteraction", "right"),
    ]
    assert [r.key for r in ds.select(category="structured", success=True)] == ["sub_01/T010"]


def test_trial_is_converted_into_the_world_frame(folder, tmp_path):
    trial = load(folder, tmp_path).trial("sub_01/T010")
    unity = hand_positions()
    hand = trial.trackers["hand"]
    # world x = Unity z - front edge (-0.35), world y = -Unity x, world z = Unity y
    np.testing.assert_allclose(hand.position[:, 0], unity[:, 2] + 0.35, atol=1e-12)
    np.testing.assert_allclose(hand.position[:, 1], -unity[:, 0], atol=1e-12)
    np.testing.assert_allclose(hand.position[:, 2], unity[:, 1], atol=1e-12)
    np.testing.assert_allclose(hand.yaw, -np.radians(10.0 * np.arange(6)), atol=1e-12)
    assert set(trial.trackers) == {"hand", "wrist", "elbow", "upper_arm"}
    assert set(trial.objects) == {"Target"} | {o.name for o in trial.scene.obstacles}
    short = trial.scene.obstacle("FailOnTouchObstacleShort")
    assert (short.x, short.y, *short.size) == pytest.approx((0.245, -0.1275, 0.05, 0.05, 0.12))
    assert trial.scene.start == pytest.approx((0.1, 0.0))
    assert trial.scene.target.position == pytest.approx((0.525, 0.0))
    assert trial.interactions[1].end_time is None and trial.interactions[1].kind == "PickedUp"


def test_archive_and_folder_give_the_same_trials(folder, tmp_path):
    archive = write_archive(folder, tmp_path / "hlp-vr-dataset.tar.xz")
    from_folder = load(folder, tmp_path)
    from_archive = load(archive, tmp_path)
    from_parent = load(tmp_path, tmp_path)  # a folder holding the archive, like ../shared/data
    assert from_archive.records == from_folder.records == from_parent.records
    a, b = from_archive.trial("sub_01/T010"), from_folder.trial("sub_01/T010")
    assert a.scene == b.scene
    np.testing.assert_array_equal(a.objects["Target"].position, b.objects["Target"].position)


def test_second_load_comes_from_the_cache_and_edits_invalidate_it(folder, tmp_path):
    assert load(folder, tmp_path).cache_status == "built"
    assert load(folder, tmp_path).cache_status == "warm"
    log = folder / "sub_01" / "T010" / "movement" / "interaction_log_T010.csv"
    log.write_text(log.read_text() + "100.05,100.06,Hand,FailOnTouchObstacleMed,Pushed\n")
    again = load(folder, tmp_path)
    assert again.cache_status == "built"
    assert again.trial("sub_01/T010").interactions[-1].kind == "Pushed"


def test_a_second_process_waits_for_the_cache_being_built_and_reads_it(folder, tmp_path):
    first = load(folder, tmp_path)
    shutil.rmtree(first.cache_path)
    statuses = []
    waiting = threading.Thread(target=lambda: statuses.append(load(folder, tmp_path).cache_status))
    with cache_lock(first.cache_path):  # a process building the cache holds this lock
        waiting.start()
        waiting.join(timeout=0.5)
        assert waiting.is_alive() and not first.cache_path.exists()  # it waits instead of parsing too
        build_cache(first.source, first.cache_path, progress=False)
    waiting.join(timeout=60)
    assert statuses == ["warm"]


def test_a_cache_another_process_wrote_meanwhile_is_kept(folder, tmp_path):
    ds = load(folder, tmp_path)
    before = (ds.cache_path / "tracks.npy").stat().st_ino
    build_cache(ds.source, ds.cache_path, progress=False)  # a reader may have it open: never replaced
    assert (ds.cache_path / "tracks.npy").stat().st_ino == before
    assert load(folder, tmp_path).cache_status == "warm"


def test_damaged_cache_is_rebuilt(folder, tmp_path):
    ds = load(folder, tmp_path)
    tracks = ds.cache_path / "tracks.npy"
    tracks.write_bytes(tracks.read_bytes()[:100])
    rebuilt = load(folder, tmp_path)
    assert rebuilt.cache_status == "built"
    assert len(rebuilt.trial("sub_01/T010").trackers["hand"]) == 6


@pytest.mark.parametrize(
    "edit",
    [
        lambda trials: [t for t in trials if t["trial"] != 10],  # a trial removed
        lambda trials: [*trials, trials[0]],  # a trial repeated
        lambda trials: [{}],
        lambda trials: 5,
    ],
    ids=["removed", "repeated", "[{}]", "5"],
)
def test_an_edited_cache_index_is_rebuilt_even_with_its_digest_updated(folder, tmp_path, edit):
    import hashlib
    import json

    ds = load(folder, tmp_path)
    index_path = ds.cache_path / "index.json"
    index = json.loads(index_path.read_text())
    index["trials"] = edit(index["trials"])
    text = json.dumps(index)
    index_path.write_text(text)
    (ds.cache_path / "index.sha256").write_text(hashlib.sha256(text.encode()).hexdigest())
    rebuilt = load(folder, tmp_path)
    assert rebuilt.cache_status == "built" and [r.key for r in rebuilt.records] == [r.key for r in ds.records]


def test_truncated_movement_file_is_reported_by_path_and_only_its_trial_dropped(folder, tmp_path):
    path = folder / "sub_01" / "T010" / "movement" / "ElbowTracker_movement_T010.csv"
    path.write_text(path.read_text()[:-12])  # cut the last line in the middle
    ds = load(folder, tmp_path)
    assert [p["path"] for p in ds.problems] == [str(path)]
    assert "sub_01/T010" not in ds and "sub_01/T011" in ds


def test_missing_file_and_missing_folder_are_reported(folder, tmp_path):
    import shutil

    missing = folder / "sub_01" / "T011" / "movement" / "Target_movement_T011.csv"
    missing.unlink()
    shutil.rmtree(folder / "sub_01" / "T005")
    ds = load(folder, tmp_path)
    reasons = {p["path"]: p["reason"] for p in ds.problems}
    assert reasons[str(folder / "sub_01/T011/movement/Target_movement_T011.csv")].startswith("missing")
    assert "folder is missing" in reasons[str(folder / "sub_01/T005")]
    assert [r.key for r in ds.records] == ["sub_01/T010"]


def test_unreadable_and_non_numeric_files_are_reported(folder, tmp_path):
    layout = folder / "sub_01" / "T010" / "scene" / "grid_objects_layout_T010.csv"
    layout.write_text(layout.read_text().replace("0.1275", "abc"))
    log = folder / "sub_01" / "T011" / "movement" / "interaction_log_T011.csv"
    log.write_bytes(b"\xff\xfe garbage")
    ds = load(folder, tmp_path)
    reasons = {p["path"]: p["reason"] for p in ds.problems}
    assert "not a number" in reasons[str(layout)]
    assert "UTF-8" in reasons[str(log)]
    assert [r.key for r in ds.records] == ["sub_01/T005"]


def set_sample(path, line: int, value: str) -> None:
    """Set the x position of line ``line`` (counting the header as 1) of the track ``path`` to ``value``."""
    lines = path.read_text().splitlines()
    fields = lines[line - 1].split(",")
    fields[1] = value
    lines[line - 1] = ",".join(fields)
    path.write_text("\n".join(lines) + "\n")


@pytest.mark.parametrize(
    ("line", "value", "reason"),
    [(4, "NaN", "line 4: non-finite value"), (3, "1e308", "line 3: a value beyond +-1e+06")],
)
def test_a_bad_sample_leaves_its_trial_out_with_the_file_and_line(folder, tmp_path, line, value, reason):
    path = folder / "sub_01" / "T010" / "movement" / "HandTracker_movement_T010.csv"
    set_sample(path, line, value)
    ds = load(folder, tmp_path)
    assert "sub_01/T010" not in ds and "sub_01/T005" in ds and "sub_01/T011" in ds
    assert ds.problems == [{"path": str(path), "reason": reason}]


def test_an_oversized_file_is_left_out_unread(folder, tmp_path, monkeypatch):
    from hlp_drake.dataset import source

    path = folder / "sub_01" / "T011" / "movement" / "HandTracker_movement_T011.csv"
    monkeypatch.setattr(source, "MAX_FILE_BYTES", path.stat().st_size - 1)
    ds = load(folder, tmp_path)
    reasons = {p["path"]: p["reason"] for p in ds.problems}
    assert "sub_01/T011" not in ds and "larger than" in reasons[str(path)]


def test_a_trial_listed_twice_in_the_results_is_left_out_with_both_lines(folder, tmp_path):
    results = folder / "sub_01" / "trial_results.csv"
    lines = results.read_text().splitlines()
    (twice,) = [line for line in lines[1:] if line.split(",")[lines[0].split(",").index("trial_num")] == "10"]
    results.write_text("\n".join([*lines, twice]) + "\n")
    ds = load(folder, tmp_path)
    assert "sub_01/T010" not in ds and "sub_01/T011" in ds
    reasons = [p["reason"] for p in ds.problems if p["path"].endswith("trial_results.csv")]
    assert len(reasons) == 2 and all("sub_01/T010 is listed more than once" in r for r in reasons)


def test_segment_trial_of_a_trial_listed_twice_names_the_results_file(folder, tmp_path):
    results = folder / "sub_01" / "trial_results.csv"
    results.write_text(results.read_text() + results.read_text().splitlines()[2] + "\n")  # T010 again
    result = run_module(
        "hlp_drake.segment",
        "--dataset",
        str(folder),
        "--trial",
        "sub_01/T010",
        "--png",
        str(tmp_path / "t.png"),
        env={"HLP_CACHE": str(tmp_path / "cache")},
    )
    assert result.returncode == 2 and not (tmp_path / "t.png").exists()
    assert (
        f"sub_01/T010 was left out of the dataset: {results}: line 3: sub_01/T010 is listed" in result.stderr
    )


def test_an_unusable_cache_folder_is_one_line_before_parsing(folder, tmp_path, monkeypatch, capsys):
    afile = tmp_path / "a-file"
    afile.write_text("not a folder")
    monkeypatch.setenv("HLP_CACHE", str(afile))
    with pytest.raises(DatasetError, match="cannot write the dataset cache in .*a-file.*HLP_CACHE"):
        Dataset(folder, progress=True)
    assert "reading VR dataset" not in capsys.readouterr().err


def test_overlapping_objects_in_a_layout_reject_the_trial(folder, tmp_path):
    layout = folder / "sub_01" / "T010" / "scene" / "grid_objects_layout_T010.csv"
    layout.write_text(layout.read_text().replace("0.2575", "0.1375"))
    ds = load(folder, tmp_path)
    assert "overlap" in ds.problems[0]["reason"] and "sub_01/T010" not in ds


def test_without_a_path_the_dataset_is_hlp_dataset_else_shared_data_beside_a_source_checkout(
    folder, tmp_path, monkeypatch
):
    from hlp_drake.dataset import source

    project = tmp_path / "project"
    project.mkdir()
    data = tmp_path / "shared" / "data"
    data.mkdir(parents=True)
    assert source.default_dataset(project) is None  # no pyproject.toml: an installed package
    (project / "pyproject.toml").write_text("")
    assert source.default_dataset(project) == data
    monkeypatch.delenv("HLP_DATASET", raising=False)
    monkeypatch.setattr(source, "default_dataset", lambda: folder)
    assert Dataset(cache_dir=tmp_path / "c", progress=False).source.path == folder
    monkeypatch.setenv("HLP_DATASET", str(tmp_path / "elsewhere"))  # the variable comes first
    with pytest.raises(DatasetError, match="elsewhere"):
        Dataset(cache_dir=tmp_path / "c", progress=False)


def test_bad_paths_raise_one_clear_error(tmp_path, monkeypatch):
    from hlp_drake.dataset import source

    monkeypatch.delenv("HLP_DATASET", raising=False)
    monkeypatch.setattr(source, "default_dataset", lambda: None)  # no ../shared/data either
    with pytest.raises(DatasetError, match="no dataset given"):
        Dataset(cache_dir=tmp_path)
    with pytest.raises(DatasetError, match="no such file or directory"):
        Dataset(tmp_path / "nowhere", cache_dir=tmp_path)
    (tmp_path / "notes.txt").write_text("hello")
    with pytest.raises(DatasetError, match="not a tar archive"):
        Dataset(tmp_path / "notes.txt", cache_dir=tmp_path)
    (tmp_path / "empty").mkdir()
    with pytest.raises(DatasetError, match="no VR dataset here"):
        Dataset(tmp_path / "empty", cache_dir=tmp_path)
    broken = tmp_path / "broken.tar.xz"
    write_archive(write_dataset(tmp_path / "d"), broken)
    broken.write_bytes(broken.read_bytes()[:400])
    with pytest.raises(DatasetError, match="cannot read the archive"):
        Dataset(broken, cache_dir=tmp_path / "c")


def test_summary_cli_missing_dataset_is_one_line(tmp_path):
    result = run_module(
        "hlp_drake.dataset",
        "summary",
        "--dataset",
        str(tmp_path / "nope"),
        "--json",
        str(tmp_path / "out.json"),
    )
    assert result.returncode == 2
    assert result.stderr.count("\n") == 1 and result.stderr.startswith("error: ")
    assert "Traceback" not in result.stderr
    assert not (tmp_path / "out.json").exists()


def test_summary_cli_reports_problems_and_counts(folder, tmp_path):
    (folder / "sub_01" / "T011" / "movement" / "Target_movement_T011.csv").unlink()
    out = tmp_path / "summary.json"
    result = run_module(
        "hlp_drake.dataset",
        "summary",
        "--dataset",
        str(folder),
        "--json",
        str(out),
        env={"HLP_CACHE": str(tmp_path / "cache")},
    )
    assert result.returncode == 0, result.stderr
    assert "warning:" in result.stderr and "Target_movement_T011.csv" in result.stderr
    import json

    summary = json.loads(out.read_text())
    assert summary["subjects"] == 1
    assert summary["categories"]["practice"] == {"trials": 1, "successes": 1}
    assert summary["categories"]["structured"] == {"trials": 1, "successes": 1}
    assert len(summary["problems"]) == 1


@pytest.mark.parametrize(
    ("arguments", "expected"),
    [
        (["--category", "unstructured", "--out", "{tmp}/d.csv"], "no successful unstructured trials"),
        (
            ["--trial", "sub_01/T010", "--png", "{tmp}/t.png"],
            "HandTracker_movement_T010.csv: line 3: non-finite value",
        ),
    ],
)
def test_segment_with_nothing_to_segment_is_one_line_and_writes_nothing(
    folder, tmp_path, arguments, expected
):
    path = folder / "sub_01" / "T010" / "movement" / "HandTracker_movement_T010.csv"
    set_sample(path, 3, "nan")  # its trial is left out: line 3
    out = tmp_path / "out"
    out.mkdir()
    argv = [a.format(tmp=out) for a in arguments]
    result = run_module(
        "hlp_drake.segment", "--dataset", str(folder), *argv, env={"HLP_CACHE": str(tmp_path / "cache")}
    )
    assert result.returncode == 2 and "Traceback" not in result.stderr, result.stderr
    (line,) = [x for x in result.stderr.splitlines() if x.startswith("error: ")]
    assert expected in line, result.stderr
    assert list(out.iterdir()) == []


@pytest.mark.parametrize(
    ("arguments", "expected"),
    [
        (["--models", "bundled"], "no usable unstructured trials to plan"),
        (["--protocol", "80_20"], "80_20 protocol needs usable structured trials of at least 3 participants"),
        (
            ["--protocol", "num_subjects"],
            "num_subjects protocol needs usable structured trials of at least 4",
        ),
        (
            ["--protocol", "unstructured", "--mode", "fixed"],
            "needs at least 4 participants with unstructured",
        ),
    ],
)
def test_evaluate_with_nothing_to_score_is_one_line_and_writes_nothing(folder, tmp_path, arguments, expected):
    out = tmp_path / "out"
    out.mkdir()
    result = run_module(
        "hlp_drake.evaluate",
        "--dataset",
        str(folder),
        *arguments,
        "--json",
        str(out / "e.json"),
        "--quiet",
        env={"HLP_CACHE": str(tmp_path / "cache")},
    )
    assert result.returncode == 2 and "Traceback" not in result.stderr, result.stderr
    assert result.stderr.strip().splitlines() == [f"error: {result.stderr.strip()[7:]}"]
    assert expected in result.stderr and list(out.iterdir()) == []
