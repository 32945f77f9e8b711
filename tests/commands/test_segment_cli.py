"""``python -m hlp_drake.segment`` end to end on the real dataset."""

from __future__ import annotations

import csv

import pytest
from conftest import run_module

pytestmark = pytest.mark.dataset


def test_segment_writes_the_decisions_csv(dataset_path, tmp_path):
    out = tmp_path / "demos.csv"
    result = run_module(
        "hlp_drake.segment",
        "--dataset",
        str(dataset_path),
        "--mode",
        "faithful",
        "--out",
        str(out),
        "--json",
        str(tmp_path / "s.json"),
    )
    assert result.returncode == 0, result.stderr
    assert "kept 1752 of 1805" in result.stdout and "rejected 11: the target never moved" in result.stdout
    rows = list(csv.DictReader(out.open()))
    assert len(rows) == 2 * 1752
    assert {"subject", "trial", "row", "decision", "element", "direction"} <= set(rows[0])
    first = next(r for r in rows if r["subject"] == "sub_01" and r["trial"] == "50")
    assert (first["row"], first["decision"], first["element"]) == ("1", "gap", "2")
    assert all(r["direction"] for r in rows if r["decision"] == "object")


def test_segment_draws_one_trial(dataset_path, tmp_path):
    png = tmp_path / "t.png"
    result = run_module(
        "hlp_drake.segment", "--dataset", str(dataset_path), "--trial", "sub_01/T050", "--png", str(png)
    )
    assert result.returncode == 0, result.stderr
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "row 2: object FailOnTouchObstacleLong-1" in result.stdout


def test_segment_unknown_trial_is_one_line(dataset_path, tmp_path):
    png = tmp_path / "t.png"
    result = run_module(
        "hlp_drake.segment", "--dataset", str(dataset_path), "--trial", "sub_99/T050", "--png", str(png)
    )
    assert result.returncode == 2
    assert result.stderr.strip().splitlines() == [
        "error: no trial 'sub_99/T050' in the dataset (expected e.g. sub_01/T050)"
    ]
    assert not png.exists()
