"""A person file (``segmentation.person_file``): scenes and a person's choices written by hand, read
into row decisions, each bad trial named with its line and left out; ``train --adapt FILE`` on it."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
import yaml
from conftest import run_module
from fuzz_support import PROFILES, STATS, check_error, run
from hypothesis import strategies as st

from hlp_drake.errors import DatasetError
from hlp_drake.learners import DecisionModels
from hlp_drake.scene.generators import generate_vr
from hlp_drake.scene.io import save_scene
from hlp_drake.segmentation.demonstration import GAP, NONE, OBJECT
from hlp_drake.segmentation.person_file import read_person_file
from hlp_drake.taskspace import TaskSpace

SEEDS = range(6)


class _Dumper(yaml.SafeDumper):
    def ignore_aliases(self, data) -> bool:  # a choice written twice is written out twice
        return True


def _dump(document: dict) -> str:
    return yaml.dump(document, Dumper=_Dumper, sort_keys=False)


def _choices(seed: int) -> list[dict]:
    """A way through VR scene ``seed``: row 1's leftmost gap, then row 2's first obstacle moved left."""
    space = TaskSpace(generate_vr(seed))
    gap = space.gaps[0][0]
    return [
        {"gap": [gap.left or "edge", gap.right or "edge"]},
        {"move": space.rows[1].members[0], "direction": "LL"},
    ]


def _write(folder: Path, trials: list[dict], **top) -> Path:
    (folder / "scenes").mkdir(parents=True, exist_ok=True)
    for seed in SEEDS:
        save_scene(generate_vr(seed), folder / "scenes" / f"vr{seed}.yaml")
    path = folder / "person.yaml"
    path.write_text(_dump({"person": "alice", **top, "trials": trials}))
    return path


def _trials() -> list[dict]:
    return [{"scene": f"scenes/vr{seed}.yaml", "choices": _choices(seed)} for seed in SEEDS]


def test_the_choices_become_the_rows_decisions(tmp_path):
    person = read_person_file(_write(tmp_path, _trials()))
    assert person.person == "alice" and person.left_out == []
    assert [t.key for t in person.demonstrations] == [f"alice/T{n:03d}" for n in range(1, 7)]
    for seed, trial in zip(SEEDS, person.demonstrations):
        space = TaskSpace(generate_vr(seed))
        first, second, *rest = trial.decisions
        assert (first.row, first.decision, first.gap) == (1, GAP, 1)
        assert (second.row, second.decision) == (2, OBJECT)
        assert (second.obstacle, second.direction) == (space.rows[1].members[0], "LL")
        assert [d.decision for d in rest] == [NONE] * (len(space.rows) - 2)


@pytest.mark.parametrize(
    ("choice", "why"),
    [
        ({"gap": ["edge", "Ghost"]}, "choices[0]: gap: names 'Ghost', which the scene does not have"),
        (
            {"move": "Ghost", "direction": "LL"},
            "choices[0]: move: names 'Ghost', which the scene does not have",
        ),
        ({"gap": ["edge", "edge"]}, "choices[0]: gap: no gap between edge and edge"),
        ({"gap": "wide"}, "choices[0]: gap: expected [left, right], two obstacle names or 'edge'"),
        ({"move": "{first}", "direction": "UP"}, "choices[0]: direction: expected one of FF, BB, LL, RR"),
        ({"move": "{first}"}, "choices[0]: expected gap: [left, right], or move: NAME and direction: DIR"),
    ],
)
def test_a_bad_choice_leaves_its_trial_out_with_file_and_line(tmp_path, choice, why):
    trials = _trials()
    first = TaskSpace(generate_vr(2)).rows[0].members[0]
    trials[2]["choices"] = [
        {k: v.format(first=first) if isinstance(v, str) else v for k, v in choice.items()}
    ]
    path = _write(tmp_path, trials)
    person = read_person_file(path)
    assert len(person.demonstrations) == 5
    (line,) = person.left_out
    start = _dump({"person": "alice", "trials": trials}).splitlines().index("- scene: scenes/vr2.yaml")
    assert line.startswith(f"{path}: line {start + 1}: trials[2]: {why}"), line


def test_two_choices_in_a_row_and_a_missing_scene_leave_their_trials_out(tmp_path):
    trials = _trials()
    trials[0]["choices"] = [trials[0]["choices"][0], dict(trials[0]["choices"][0])]
    trials[1]["scene"] = "scenes/nowhere.yaml"
    person = read_person_file(_write(tmp_path, trials))
    assert len(person.demonstrations) == 4
    assert re.fullmatch(
        r".*: line \d+: trials\[0\]: choices\[1\]: a second choice in row 1", person.left_out[0]
    )
    assert "trials[1]: " in person.left_out[1] and "nowhere.yaml" in person.left_out[1]


def test_a_malformed_file_is_refused_in_one_line_per_problem(tmp_path):
    path = _write(tmp_path, _trials())
    path.write_text("person: [\n")
    with pytest.raises(DatasetError, match=r"not valid YAML at line 2"):
        read_person_file(path)
    path.write_text(yaml.safe_dump({"person": "a b", "left_handed": "yes", "trials": []}))
    with pytest.raises(DatasetError) as error:
        read_person_file(path)
    assert [p.split(": ", 1)[1].split(":")[0] for p in error.value.problems] == [
        "person",
        "left_handed",
        "trials",
    ]


@pytest.mark.slow
def test_adapt_on_a_person_file_then_refuse_one_with_too_few_trials(tmp_path):
    path = _write(tmp_path / "demos", _trials())
    out = tmp_path / "models"
    result = run_module("hlp_drake.train", "--adapt", str(path), "--out", str(out))
    assert result.returncode == 0, result.stderr
    assert "adapted to alice from 6 trials (12 row choices, 0 left out)" in result.stdout
    sha = re.search(r"models.json SHA-256 ([0-9a-f]{64})", result.stdout).group(1)
    assert "alice" in DecisionModels.load(out, sha256=sha).subjects_
    few = _write(tmp_path / "few", _trials()[:4])
    refused = run_module("hlp_drake.train", "--adapt", str(few), "--out", str(tmp_path / "none"))
    assert refused.returncode == 2 and refused.stdout == ""
    assert refused.stderr == "error: 4 usable trial(s) of alice; adapting needs at least 5\n"
    assert not (tmp_path / "none").exists()


def _mutated(data):
    """A drawn value put at a drawn place of the person file's document."""
    junk = st.one_of(
        st.none(),
        st.booleans(),
        st.integers(-3, 10),
        st.text(max_size=8),
        st.lists(st.text(max_size=4), max_size=3),
    )
    document = {"person": "alice", "trials": _trials()}
    where = data.draw(st.sampled_from(["person", "left_handed", "trial", "scene", "choice", "field"]))
    value = data.draw(junk)
    index = data.draw(st.integers(0, len(SEEDS) - 1))
    if where in ("person", "left_handed"):
        document[where] = value
    elif where == "trial":
        document["trials"][index] = value
    elif where == "scene":
        document["trials"][index]["scene"] = value
    elif where == "choice":
        document["trials"][index]["choices"][data.draw(st.integers(0, 1))] = value
    else:
        choice = document["trials"][index]["choices"][data.draw(st.integers(0, 1))]
        choice[data.draw(st.sampled_from(["gap", "move", "direction", "extra"]))] = value
    return document


@pytest.mark.parametrize("profile", PROFILES)
def test_a_mutated_person_file_is_read_or_refused_never_more(tmp_path, profile):
    scenes = _write(tmp_path, _trials()).parent
    path = scenes / "mutated.yaml"

    def check(data) -> None:
        STATS["person files mutated"] += 1
        path.write_text(_dump(_mutated(data)))
        try:
            person = read_person_file(path)
        except DatasetError as error:
            check_error(error)
            return
        assert len(person.demonstrations) + len(person.left_out) == len(SEEDS)
        assert all(line.startswith(f"{path}: line ") for line in person.left_out)
        STATS["person file trials left out"] += len(person.left_out)

    run(profile, (25, 400), st.data(), check)
