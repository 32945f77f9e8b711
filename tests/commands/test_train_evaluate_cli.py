"""``python -m hlp_drake.train`` and ``python -m hlp_drake.evaluate`` end to end on the real dataset."""

from __future__ import annotations

import csv
import json

import pytest
from conftest import run_module

from hlp_drake.learners import DecisionModels

pytestmark = pytest.mark.dataset


def test_train_on_some_subjects(dataset_path, tmp_path):
    out = tmp_path / "models"
    result = run_module(
        "hlp_drake.train",
        "--dataset",
        str(dataset_path),
        "--preset",
        "paper",
        "--subjects",
        "sub_01",
        "sub_02",
        "sub_03",
        "--out",
        str(out),
    )
    assert result.returncode == 0, result.stderr
    assert "of 3 subjects" in result.stdout
    models = DecisionModels.load(out)
    assert models.subjects_ == ["sub_01", "sub_02", "sub_03"] and models.settings.balance_gap_object
    assert models.planner == "paper" and "trials: structured" in result.stdout
    bad = run_module(
        "hlp_drake.train", "--dataset", str(dataset_path), "--subjects", "sub_05", "--out", str(out)
    )
    assert bad.returncode == 2 and bad.stderr.strip() == "error: unknown subjects: sub_05"


def test_evaluate_one_split(dataset_path, tmp_path):
    report, rows = tmp_path / "e.json", tmp_path / "p.csv"
    result = run_module(
        "hlp_drake.evaluate",
        "--dataset",
        str(dataset_path),
        "--splits",
        "1",
        "--seed",
        "3",
        "--preset",
        "paper",
        "--json",
        str(report),
        "--csv",
        str(rows),
        "--quiet",
    )
    assert result.returncode == 0, result.stderr
    figures = json.loads(report.read_text())
    assert list(figures["results"]) == ["19/5"]
    planners = figures["results"]["19/5"]
    assert set(planners) == {"hlp", "nearest_gap", "majority", "ceiling"}
    for key in (
        "gap_accuracy",
        "object_accuracy",
        "shlp",
        "shlp_decision",
        "shlp_element",
        "shlp_element_plan",
        "shlp_plan",
    ):
        assert set(planners["hlp"][key]) == {"mean", "std"} and 0.0 <= planners["hlp"][key]["mean"] <= 1.0
    hlp, rule = planners["hlp"], planners["nearest_gap"]
    assert (
        hlp["planning_time_s"]["median"] > 0.0 and "planning_time_s" not in rule
    )  # only the planner is timed
    assert hlp["shlp"]["mean"] > 0.6 and hlp["gap_accuracy"]["mean"] > 0.85  # well above chance
    assert hlp["shlp_plan"]["mean"] > rule["shlp_plan"]["mean"] + 0.2  # people mostly move obstacles here
    ceiling = planners["ceiling"]  # the training people on the shared layouts; no row matching here
    coverage = ceiling["coverage"]
    assert 0 < coverage["layout"] == coverage["rows"] < coverage["rows_total"] and "threshold" not in coverage
    same = ceiling["same_rows"]
    assert set(same) == {"hlp", "nearest_gap", "majority"} and "planning_time_s" not in ceiling
    assert ceiling["shlp"]["mean"] > same["hlp"]["shlp"]["mean"] > same["nearest_gap"]["shlp"]["mean"]
    assert "ceiling: the training people's choices on" in result.stdout
    test_subjects = set(figures["splits_subjects"]["19/5"][0]["test"])
    assert len(test_subjects) == 5 and not test_subjects & set(figures["splits_subjects"]["19/5"][0]["train"])
    table = list(csv.DictReader(rows.open()))
    assert {r["subject"] for r in table} == test_subjects
    assert {r["planner"] for r in table} == {"hlp", "nearest_gap", "majority", "ceiling"}
    ceiling_rows = [r for r in table if r["planner"] == "ceiling"]
    assert len(ceiling_rows) == coverage["rows"]
    assert "Cg" in result.stdout and "0.95" in result.stdout  # the paper's figures beside


def test_evaluate_the_bundled_models_on_unstructured_trials(dataset_path, unstructured, tmp_path):
    report, picture = tmp_path / "u.json", tmp_path / "u.png"
    result = run_module(
        "hlp_drake.evaluate",
        "--dataset",
        str(dataset_path),
        "--models",
        "bundled",
        "--category",
        "unstructured",
        "--json",
        str(report),
        "--png",
        str(picture),
        "--quiet",
    )
    assert result.returncode == 0, result.stderr
    figures = json.loads(report.read_text())["results"]["unstructured"]
    # Trained on every trial there is (these people's too): far above the one-line rule.
    assert figures["hlp"]["shlp_plan"]["mean"] > figures["nearest_gap"]["shlp_plan"]["mean"] + 0.1
    assert figures["hlp"]["row_in_distribution"]["mean"] > 0.9  # these trials were trained on
    assert picture.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    bad = run_module(
        "hlp_drake.evaluate",
        "--dataset",
        str(dataset_path),
        "--models",
        str(tmp_path / "none"),
        "--json",
        str(report),
        "--quiet",
    )
    assert bad.returncode == 2 and bad.stderr.count("\n") == 1 and "model file not found" in bad.stderr


@pytest.mark.slow
def test_the_unstructured_protocol_beats_both_baselines(dataset_path, unstructured, tmp_path):
    report = tmp_path / "t.json"
    result = run_module(
        "hlp_drake.evaluate",
        "--dataset",
        str(dataset_path),
        "--protocol",
        "unstructured",
        "--folds",
        "2",
        "--json",
        str(report),
        "--quiet",
    )
    assert result.returncode == 0, result.stderr
    figures = json.loads(report.read_text())["results"]
    for setting in ("a", "b"):
        hlp = figures[setting]["hlp"]["shlp_plan"]["mean"]
        assert (
            hlp
            > figures[setting]["nearest_gap"]["shlp_plan"]["mean"]
            > figures[setting]["majority"]["shlp_plan"]["mean"]
        )
