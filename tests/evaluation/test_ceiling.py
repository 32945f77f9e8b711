"""The human ceiling on hand-made rows: the consensus and the scores known exactly."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from hlp_drake.evaluation import Ceiling, consensus, layout_key, metrics_of, score_trial
from hlp_drake.evaluation.ceiling import LAYOUT, MATCHED
from hlp_drake.scene.model import Scene, SceneObject, Table
from hlp_drake.segmentation.arm import LinkLengths
from hlp_drake.segmentation.demonstration import GAP, OBJECT, Demonstration, RowDecision
from hlp_drake.taskspace import TaskSpace

TABLE = Table(0.6, 0.74, 0.73)
TARGET = SceneObject("Target", "cylinder", 0.525, 0.0, (0.05, 0.05, 0.085))


def layout(shift: float = 0.0, spread: float = 1.0) -> Scene:
    """Two rows of three boxes (the VR study's structured kind); ``shift`` moves every obstacle
    sideways, ``spread`` scales their lateral places."""

    def box(name: str, x: float, y: float, width: float) -> SceneObject:
        return SceneObject(name, "box", x, spread * y + shift, (0.05, width, 0.12))

    near = [
        box("Short", 0.245, 0.1275, 0.05),
        box("Med", 0.245, 0.2575, 0.1),
        box("Long", 0.245, -0.1925, 0.15),
    ]
    far = [box("Short-1", 0.405, -0.2175, 0.05), box("Med-1", 0.405, -0.0575, 0.1)]
    far.append(box("Long-1", 0.405, 0.1725, 0.15))
    return Scene(TABLE, (0.1, 0.0), TARGET, (*near, *far), name="layout")


def demo(key: str, scene: Scene, *choices: tuple[str, str]) -> Demonstration:
    """A demonstration of ``scene`` that made ``choices`` (per row: ("gap", index) or ("object",
    name)); only what the scores read is real."""
    space = TaskSpace(scene)
    decisions = tuple(
        RowDecision(row, GAP, gap=int(e))
        if d == GAP
        else RowDecision(row, OBJECT, obstacle=e, direction="FL")
        for row, (d, e) in enumerate(choices, start=1)
    )
    flags = tuple(
        tuple(d.decision == GAP and g.index == d.gap for g in gaps) for d, gaps in zip(decisions, space.gaps)
    )
    return Demonstration(
        key,
        "fixed",
        replace(scene, name=key),
        False,
        decisions,
        (),
        flags,
        LinkLengths(0.3, 0.3),
        0,
        np.zeros((1, 2)),
    )


def test_a_unanimous_consensus_is_everyone_s_choice():
    assert consensus([(GAP, "2")] * 5, {}) == (GAP, "2")


def test_the_consensus_weighs_decision_and_element_as_shlp_does():
    # Pairs: gap 1 three times, but obstacles five: A scores 5 + 2 = 7 against gap 1's 3 + 3 = 6.
    votes = [(GAP, "1")] * 3 + [(OBJECT, "A")] * 2 + [(OBJECT, "B")] * 2 + [(OBJECT, "C")]
    lateral = {(OBJECT, "A"): 0.1, (OBJECT, "B"): -0.1, (OBJECT, "C"): 0.0}
    assert consensus(votes, lateral) == (OBJECT, "A")
    assert consensus(votes, {**lateral, (OBJECT, "B"): 0.2}) == (OBJECT, "B")  # the tie: the leftmost


def test_the_tie_rule_prefers_the_shared_element_then_a_gap():
    # gap 1: 2 + 2; object A: 3 + 1 (decisions 3, pair 1): equal, the larger pair count wins.
    assert consensus([(GAP, "1")] * 2 + [(OBJECT, "A"), (OBJECT, "B"), (OBJECT, "C")], {}) == (GAP, "1")
    assert consensus([(GAP, "3"), (OBJECT, "A")], {}) == (GAP, "3")  # all equal: a gap first
    with pytest.raises(ValueError):
        consensus([], {})


def test_the_layout_is_the_geometry_to_the_millimetre_not_the_name():
    assert layout_key(layout()) == layout_key(replace(layout(), name="other"))
    assert layout_key(layout()) != layout_key(layout(shift=0.002))


def _score(ceiling: Ceiling, person: Demonstration):
    plan, how = ceiling.plan(person)
    return score_trial(person, plan, faithful=False, rows=set(how)), how


def test_agreeing_with_unanimous_others_scores_one_and_disagreeing_on_a_row_halves_it():
    others = [demo(f"sub_0{k}/T020", layout(), (GAP, "2"), (OBJECT, "Med-1")) for k in range(1, 4)]
    ceiling = Ceiling.of(others)
    outcome, how = _score(ceiling, demo("sub_09/T031", layout(), (GAP, "2"), (OBJECT, "Med-1")))
    assert how == {1: LAYOUT, 2: LAYOUT}
    assert metrics_of([outcome]) == dict.fromkeys(metrics_of([outcome]), 1.0)
    outcome, _ = _score(ceiling, demo("sub_09/T031", layout(), (GAP, "2"), (GAP, "3")))
    figures = metrics_of([outcome])
    assert (figures["shlp"], figures["shlp_decision"], figures["shlp_element"]) == (0.5, 0.5, 0.5)
    assert outcome.object_total == 3 + 3 and outcome.object_correct == 3 + 2  # Med-1 is not moved


def test_the_person_never_votes_and_an_unshared_layout_is_not_scored():
    others = [
        demo("sub_01/T020", layout(), (GAP, "1"), (GAP, "1")),
        demo("sub_02/T020", layout(), (GAP, "1"), (GAP, "1")),
    ]
    own = [demo("sub_09/T050", layout(), (GAP, "3"), (GAP, "2"))] * 5  # the person's other trials
    ceiling = Ceiling.of([*others, *own])
    outcome, _ = _score(ceiling, demo("sub_09/T031", layout(), (GAP, "3"), (GAP, "2")))
    figures = metrics_of([outcome])  # the others went through gap 1 every time: the decision only
    assert (figures["shlp"], figures["shlp_decision"], figures["shlp_element"]) == (0.5, 1.0, 0.0)
    _, how = ceiling.plan(demo("sub_09/T031", layout(shift=0.003), (GAP, "3"), (GAP, "2")))
    assert how == {}


def test_scoring_some_rows_counts_only_their_gaps_and_obstacles():
    person = demo("sub_09/T031", layout(), (GAP, "2"), (OBJECT, "Med-1"))
    ceiling = Ceiling.of([demo("sub_01/T020", layout(), (GAP, "2"), (OBJECT, "Long-1"))])
    plan, _ = ceiling.plan(person)
    gaps = [len(g) for g in TaskSpace(person.scene).gaps]
    first = score_trial(person, plan, faithful=False, rows={1})
    assert [r.row for r in first.rows] == [1] and (first.gap_total, first.object_total) == (gaps[0], 3)
    assert metrics_of([first])["shlp"] == 1.0
    both = score_trial(person, plan, faithful=False)
    assert both.gap_total == sum(gaps) and metrics_of([both])["shlp"] == 0.75  # row 2: decision only


def test_rows_without_a_shared_layout_are_matched_to_the_nearest_within_the_threshold():
    pool = [
        demo("sub_01/T020", layout(), (GAP, "3"), (GAP, "1")),
        demo("sub_02/T021", layout(spread=0.8), (GAP, "1"), (GAP, "2")),
        demo("sub_03/T022", layout(spread=1.1), (GAP, "2"), (GAP, "3")),
    ]
    person = demo("sub_09/T120", layout(shift=0.003), (GAP, "3"), (GAP, "1"))
    assert Ceiling.of(pool).plan(person)[1] == {}  # no matching: nothing shared
    ceiling = Ceiling.of(pool, match=True)
    assert ceiling.threshold > 0.0
    outcome, how = _score(ceiling, person)
    assert how == {1: MATCHED, 2: MATCHED}  # sub_01's rows, 3 mm away, are the nearest
    assert metrics_of([outcome])["shlp"] == 1.0
    far = demo("sub_09/T121", layout(shift=0.06, spread=0.6), (GAP, "1"), (GAP, "1"))
    assert ceiling.plan(far)[1] == {}  # nearer no one than the people's rows are to each other
