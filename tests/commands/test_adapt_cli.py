"""``python -m hlp_drake.train --adapt DEMOS``: one person's VR logs from the real dataset, adapted
on, and each kind of bad input named with its file and line; ``run_scene --models DIR`` on the result."""

from __future__ import annotations

import csv
import io
import re
import shutil
from pathlib import Path

import pytest
from conftest import run_module
from fuzz_support import PROFILES, STATS, check_error, damage_csv, run
from hypothesis import strategies as st

from hlp_drake.errors import DatasetError
from hlp_drake.learners import DecisionModels
from hlp_drake.segmentation.person import read_person

pytestmark = pytest.mark.dataset

PERSON = "sub_15"
TRIALS = range(10, 30)  # T010-T029: 10 successful reaches, 10 failed
GOOD = (14, 15, 16, 17, 18, 21, 22)  # successful reaches among them
FUZZED = GOOD[:3]  # the trials of the fuzzed folders


@pytest.fixture(scope="session")
def person_files(dataset_path) -> dict[str, bytes]:
    """The files of ``PERSON``'s trials ``TRIALS`` (dataset-relative path: content), their rows of
    trial_results.csv and participant_list.csv only."""
    from hlp_drake.dataset.source import resolve_source

    wanted = re.compile(rf"^{PERSON}/T0(\d\d)/")
    files = {}
    for relative, _, content in resolve_source(dataset_path).files():
        match = wanted.match(relative)
        if (match and int(match.group(1)) in TRIALS) or relative in (
            "participant_list.csv",
            f"{PERSON}/trial_results.csv",
        ):
            files[relative] = content  # a later part's file replaces an earlier one's
    if len(files) < 10:
        pytest.fail(f"the dataset has no trials {PERSON}/T010-T029")
    return files


def _rows(content: bytes, keep) -> bytes:
    rows = list(csv.reader(io.StringIO(content.decode("utf-8-sig"))))
    out = io.StringIO()
    csv.writer(out, lineterminator="\n").writerows([rows[0], *(r for r in rows[1:] if keep(r))])
    return out.getvalue().encode()


def demos(files: dict[str, bytes], folder: Path, trials=TRIALS) -> Path:
    """A DEMOS folder of ``PERSON``'s ``trials``: their folders, trial_results.csv listing them."""
    header = next(csv.reader(io.StringIO(files[f"{PERSON}/trial_results.csv"].decode("utf-8-sig"))))
    column = header.index("trial_num")
    for relative, content in files.items():
        if relative == "participant_list.csv":
            content = _rows(content, lambda r: r[0] == PERSON)
        elif relative.endswith("trial_results.csv"):
            content = _rows(content, lambda r: int(r[column]) in trials)
        elif int(relative.split("/")[1][1:]) not in trials:
            continue
        path = folder / relative
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(content)
    return folder


def adapt(folder: Path, out: Path, *more: str):
    return run_module("hlp_drake.train", "--adapt", str(folder), "--out", str(out), *more)


@pytest.mark.slow
def test_adapt_on_a_persons_trials_then_run_a_scene_with_the_pinned_models(person_files, tmp_path):
    folder, out = demos(person_files, tmp_path / "demos"), tmp_path / "models"
    result = adapt(folder, out)
    assert result.returncode == 0, result.stderr
    assert f"adapted to {PERSON} from 10 trials" in result.stdout and "10 left out" in result.stdout
    assert f"left out: {folder / PERSON / 'T010'}: the reach did not succeed (outcome 'ArmInteraction')" in (
        result.stderr.splitlines()
    )
    sha = re.search(r"models.json SHA-256 ([0-9a-f]{64})", result.stdout).group(1)
    models = DecisionModels.load(out, sha256=sha)
    assert models.planner == "rows" and PERSON in models.subjects_
    run = run_module(
        "hlp_drake.run_scene",
        "--models",
        str(out),
        "--models-sha256",
        sha,
        "--low-level",
        "trajopt",
        "--quiet",
    )
    assert run.returncode == 0, run.stderr
    assert "plan: start ->" in run.stdout and "verdict: reach success" in run.stdout
    (out / "models.npz").write_bytes((out / "models.npz").read_bytes()[:-8] + b"tampered")
    tampered = run_module("hlp_drake.run_scene", "--models", str(out), "--models-sha256", sha)
    assert tampered.returncode == 2 and tampered.stdout == ""
    assert tampered.stderr == (
        f"error: {out / 'models.npz'}: checksum mismatch (the file was modified or damaged)\n"
    )


def test_a_damaged_file_leaves_its_trial_out_with_its_path_and_line(person_files, tmp_path):
    folder = demos(person_files, tmp_path / "demos", trials=GOOD)
    layout = folder / PERSON / "T014" / "scene" / "grid_objects_layout_T014.csv"
    lines = layout.read_text().splitlines()
    lines[2] = ",".join([lines[2].split(",")[0], "abc", *lines[2].split(",")[2:]])
    layout.write_text("\n".join(lines) + "\n")
    result = adapt(folder, tmp_path / "models")
    assert result.returncode == 0, result.stderr
    assert result.stderr == f"left out: {layout}: line 3: not a number: 'abc'\n"
    assert f"from {len(GOOD) - 1} trials" in result.stdout


def test_an_empty_file_leaves_its_trial_out(person_files, tmp_path):
    folder = demos(person_files, tmp_path / "demos", trials=GOOD)
    log = folder / PERSON / "T015" / "movement" / "interaction_log_T015.csv"
    log.write_bytes(b"")
    result = adapt(folder, tmp_path / "models")
    assert result.returncode == 0, result.stderr
    assert result.stderr == f"left out: {log}: empty file\n"


def test_an_object_the_layout_lacks_leaves_its_trial_out(person_files, tmp_path):
    folder = demos(person_files, tmp_path / "demos", trials=GOOD)
    log = folder / PERSON / "T016" / "movement" / "interaction_log_T016.csv"
    header, *rows = log.read_text().splitlines()
    log.write_text("\n".join([header, "1.0,2.0,Hand,Ghost,PickedUp", *rows]) + "\n")
    result = adapt(folder, tmp_path / "models")
    assert result.returncode == 0, result.stderr
    assert result.stderr == (
        f"left out: {log}: line 2: names 'Ghost', which the scene does not have: trial skipped\n"
    )


def test_too_few_trials_are_refused_in_one_line(person_files, tmp_path):
    out = tmp_path / "models"
    result = adapt(demos(person_files, tmp_path / "demos", trials=GOOD[:3]), out)
    assert result.returncode == 2 and result.stdout == ""
    assert result.stderr == f"error: 3 usable trial(s) of {PERSON}; adapting needs at least 5\n"
    assert not out.exists()


def test_damaged_trials_that_leave_too_few_are_named_then_refused(person_files, tmp_path):
    folder = demos(person_files, tmp_path / "demos", trials=GOOD[:5])
    log = folder / PERSON / "T014" / "movement" / "interaction_log_T014.csv"
    log.write_bytes(b"")
    result = adapt(folder, tmp_path / "models")
    assert result.returncode == 2
    assert result.stderr.splitlines() == [
        f"left out: {log}: empty file",
        f"error: 4 usable trial(s) of {PERSON}; adapting needs at least 5",
    ]


def test_an_empty_or_missing_folder_and_two_people_are_refused(person_files, tmp_path):
    empty = tmp_path / "empty"
    empty.mkdir()
    result = adapt(empty, tmp_path / "models")
    assert result.returncode == 2 and result.stderr.startswith(f"error: {empty}: no VR dataset here")
    missing = adapt(tmp_path / "nowhere", tmp_path / "models")
    assert missing.returncode == 2
    assert missing.stderr.startswith(f"error: {tmp_path / 'nowhere'}: no such folder (expected one person's")
    two = demos(person_files, tmp_path / "two", trials=GOOD)
    shutil.copytree(two / PERSON, two / "sub_99")
    both = adapt(two, tmp_path / "models")
    assert both.returncode == 2
    assert both.stderr == (
        f"error: {two}: trials of 2 people ({PERSON}, sub_99); adapt to one person at a time\n"
    )


def _check_damaged_trial(case, files, folder: Path) -> None:
    trial, kind, data = case
    STATS["demonstration files damaged"] += 1
    root = demos(files, folder / f"demos{STATS['demonstration files damaged']}", trials=FUZZED)
    trial_folder = root / PERSON / f"T{trial:03d}"
    path = data.draw(st.sampled_from(sorted((trial_folder / kind).iterdir())))
    path.write_text(damage_csv(path.read_text(), data.draw), encoding="utf-8", errors="surrogateescape")
    try:
        person = read_person(root)
    except DatasetError as error:
        check_error(error)
        raise AssertionError(f"one damaged trial refused the whole folder: {error.problems}") from None
    kept = {d.key for d in person.demonstrations}
    assert kept >= {f"{PERSON}/T{n:03d}" for n in FUZZED if n != trial}
    if f"{PERSON}/T{trial:03d}" not in kept:
        STATS["demonstrations left out"] += 1
        assert any(line.startswith(str(trial_folder)) for line in person.left_out), person.left_out
    shutil.rmtree(root)


@pytest.mark.parametrize("profile", PROFILES)
def test_a_damaged_demonstration_file_leaves_only_its_trial_out_named(profile, person_files, tmp_path):
    strategy = st.tuples(st.sampled_from(FUZZED), st.sampled_from(["scene", "movement"]), st.data())
    run(profile, (6, 60), strategy, lambda case: _check_damaged_trial(case, person_files, tmp_path))
