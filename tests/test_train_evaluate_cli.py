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
    result = run_module("hlp_drake.train", "--dataset", str(dataset_path), "--preset", "paper",
                        "--subjects", "sub_01", "sub_02", "sub_03", "--out", str(out))
    assert result.returncode == 0, result.stderr
    assert "of 3 subjects" in result.stdout
    models = DecisionModels.load(out)
    assert models.subjects == ["sub_01", "sub_02", "sub_03"] and models.settings.balance_gap_object
    bad = run_module("hlp_drake.train", "--dataset", str(dataset_path), "--subjects", "sub_05", "--out", str(out))
    assert bad.returncode == 2 and bad.stderr.strip() == "error: unknown subjects: sub_05"


def test_evaluate_one_split(dataset_path, tmp_path):
    report, predictions = tmp_path / "e.json", tmp_path / "p.csv"
    result = run_module("hlp_drake.evaluate", "--dataset", str(dataset_path), "--splits", "1", "--seed", "3", "--preset", "paper",
                        "--json", str(report), "--predictions", str(predictions), "--quiet")
    assert result.returncode == 0, result.stderr
    figures = json.loads(report.read_text())
    for key in ("gap_accuracy", "object_accuracy", "shlp", "shlp_decision", "shlp_element", "shlp_element_plan"):
        assert set(figures[key]) == {"mean", "std"} and 0.0 <= figures[key]["mean"] <= 1.0
    assert figures["shlp"]["mean"] > 0.6 and figures["gap_accuracy"]["mean"] > 0.85  # well above chance
    test_subjects = set(figures["splits_subjects"][0]["test"])
    assert len(test_subjects) == 5 and not test_subjects & set(figures["splits_subjects"][0]["train"])
    rows = list(csv.DictReader(predictions.open()))
    assert {r["subject"] for r in rows} == test_subjects
    assert set(rows[0]) == {"split", "subject", "trial", "row", "human_decision", "human_element", "hlp_decision",
                            "hlp_element"}
    assert "Cg accuracy" in result.stdout and "0.95" in result.stdout
