"""A study's summary and plots: the figures per condition and series match the rows, the paper's beside
its two series, the ratios of the initialisers' times, and any grid's series."""

from __future__ import annotations

import json

import pandas as pd
import pytest
from job_support import cheap_job, run_experiment, settings

from hlp_drake.experiments.study import Study, load_study
from hlp_drake.experiments.summary import summarise, summary_markdown


def _series(condition: dict, planner: str) -> dict:
    (series,) = [s for s in condition["series"] if s["cell"]["planner"] == planner]
    return series["stats"]


def test_summary_matches_the_csv_and_shows_the_paper_numbers(tmp_path):
    run_experiment(settings("gen2", scenes=4, objects=(5, 9)), tmp_path, job=cheap_job)
    frame = pd.read_csv(tmp_path / "results.csv")
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["table"].startswith("Table III") and summary["study"] == "gen2"
    for condition in summary["conditions"]:
        assert [s["label"] for s in condition["series"]] == ["HLP", "STO (straight line)"]
        for series in condition["series"]:
            stats, planner = series["stats"], series["cell"]["planner"]
            group = frame[(frame.objects == condition["objects"]) & (frame.planner == planner)]
            assert stats["n"] == len(group) == 4
            assert stats["success_pct"] == pytest.approx(100 * group.success.mean())
            assert stats["total_s"] == pytest.approx(group.total_s.mean(), abs=1e-4)
            assert stats["init_s"] + stats["optimise_s"] == pytest.approx(stats["total_s"], abs=2e-4)
            assert 0 < stats["verify_s"] == pytest.approx(group.verify_s.mean(), abs=1e-4)
            assert stats["paper"]["total_s"] is None
        means = {
            p: frame[(frame.objects == condition["objects"]) & (frame.planner == p)].total_s.mean()
            for p in ("hlp", "sto")
        }
        (ratio,) = condition["ratios"]
        assert ratio["of"] == "HLP / STO (straight line)"
        assert ratio["total"] == pytest.approx(means["hlp"] / means["sto"], rel=1e-3)
        searching = {
            p: (group.total_s - group.verify_s).mean()
            for p, group in frame[frame.objects == condition["objects"]].groupby("planner")
        }
        assert ratio["total_without_verification"] == pytest.approx(
            searching["hlp"] / searching["sto"], rel=1e-3
        )
    papers = {
        c["objects"]: tuple(_series(c, p)["paper"]["success_pct"] for p in ("hlp", "sto"))
        for c in summary["conditions"]
    }
    assert papers == {5: (93.0, 96.0), 9: (95.0, 98.0)}
    markdown = (tmp_path / "summary.md").read_text()
    assert "| 5 objects | HLP | 4 |" in markdown and "(93)" in markdown and "n/a" in markdown
    for name in ("success.png", "times.png"):
        data = (tmp_path / name).read_bytes()
        assert data.startswith(b"\x89PNG\r\n\x1a\n") and len(data) > 10_000


def _row(i: int, planner: str, initial: str, **changes) -> dict:
    row = {
        "scene": f"gen1-{i}",
        "objects": 6,
        "planner": planner,
        "success": i != 0,
        "failure_reason": None,
        "init_s": 0.5,
        "optimise_s": 1.0 if initial == "hlp" else 10.0,
        "total_s": 1.5 if initial == "hlp" else 10.5,
        "verify_s": 0.6 if initial == "hlp" else 2.0,
        "execute_s": 3.0,
        "generator": "gen1",
        "robot": "mobile_ur5",
        "initial": initial,
        "low_level": "sto",
        "execution": "open",
        "perception": "truth",
        "model_error": None,
        "world": "reference",
    }
    return {**row, **changes}


def test_gen1_summary_has_table_ii_paper_figures():
    rows = [_row(i, p, initial) for i in range(4) for p, initial in (("hlp", "hlp"), ("sto", "line"))]
    nan = float("nan")
    crashed = {"failure_reason": "crashed: RuntimeError: x", "init_s": nan, "optimise_s": nan, "total_s": nan}
    rows.append(_row(4, "hlp", "hlp", success=False, verify_s=nan, **crashed))
    (condition,) = summarise(load_study("gen1"), rows)["conditions"]
    hlp, sto = _series(condition, "hlp"), _series(condition, "sto")
    assert hlp["paper"] == {"success_pct": 94.0, "init_s": 0.59, "optimise_s": 0.97, "total_s": 1.56}
    assert sto["paper"] == {"success_pct": 84.0, "init_s": 0.04, "optimise_s": 17.84, "total_s": 17.88}
    assert (hlp["n"], hlp["success_pct"], hlp["crashed"], hlp["total_s"]) == (5, 60.0, 1, 1.5)
    (ratio,) = condition["ratios"]
    assert ratio["total"] == pytest.approx(1.5 / 10.5, abs=1e-4)
    assert ratio["total_without_verification"] == pytest.approx(0.9 / 8.5, abs=1e-4)
    assert (hlp["verify_s"], sto["verify_s"]) == (0.6, 2.0)
    assert ratio["paper"] == pytest.approx(1.56 / 17.88, abs=1e-4)
    assert hlp["success_ci95"][0] < 60.0 < hlp["success_ci95"][1]


def test_the_summary_counts_the_models_accepts_and_the_false_accepts_per_world():
    rows = [
        _row(
            i, "hlp", "hlp", world=world, success=ok, model_success=accepted, false_accept=accepted and not ok
        )
        for i, (ok, accepted) in enumerate([(True, True), (False, True), (False, False), (True, True)])
        for world in ("reference", "model")
    ]
    summary = summarise(
        Study(name="w", generators=("gen1",), initialisers=("hlp",), world=("reference", "model")), rows
    )
    (condition,) = summary["conditions"]
    assert sorted(s["cell"]["world"] for s in condition["series"]) == ["model", "reference"]
    for series in condition["series"]:
        assert (series["stats"]["model_accepts"], series["stats"]["false_accepts"]) == (3, 1)
    markdown = summary_markdown(summary)
    assert "| model accepted | false accepts (model accepted, world failed) |" in markdown
    assert "| HLP, reference | reference | 0.0 | 0.60 | 3 of 4 | 1 of 3 |" in markdown


def test_a_grid_of_robots_and_low_level_planners_gets_a_series_per_cell_and_a_ratio_per_pair():
    rows = [
        _row(i, label, initial, robot=robot, low_level=low_level)
        for i in range(2)
        for robot in ("mobile_ur5", "panda")
        for initial, low_level, label in (
            ("hlp", "sto", "hlp"),
            ("line", "sto", "sto"),
            ("hlp", "sketch", "hlp+sketch"),
            ("line", "sketch", "line+sketch"),
        )
    ]
    study = Study(name="grid", robots=("mobile_ur5", "panda"), low_level=("sto", "sketch"))
    summary = summarise(study, rows)
    (condition,) = summary["conditions"]
    labels = [s["label"] for s in condition["series"]]
    assert len(labels) == 8 and "HLP, panda" in labels and "hlp+sketch, mobile_ur5" in labels
    assert sorted(r["of"] for r in condition["ratios"]) == [
        "HLP, mobile_ur5 / STO (straight line), mobile_ur5",
        "HLP, panda / STO (straight line), panda",
        "hlp+sketch, mobile_ur5 / line+sketch, mobile_ur5",
        "hlp+sketch, panda / line+sketch, panda",
    ]
    sketch = next(s for s in condition["series"] if s["label"] == "hlp+sketch, panda")
    assert sketch["stats"]["paper"]["success_pct"] is None  # the paper ran the STO only
    markdown = summary_markdown(summary)
    assert "| Gen I (6 objects) | hlp+sketch, panda | 2 |" in markdown
    assert summary["table"] == "grid"


def test_the_paper_is_beside_its_own_conditions_only_and_a_study_of_one_initialiser_has_no_ratios():
    rows = [_row(i, "hlp", "hlp", execution=execution) for i in range(2) for execution in ("open", "closed")]
    rows += [_row(i, "hlp", "hlp", generator="gen2", objects=5, scene=f"gen2-5-{i}") for i in range(2)]
    study = Study(
        name="mixed", generators=("gen1", "gen2"), initialisers=("hlp",), execution=("open", "closed")
    )
    summary = summarise(study, rows)
    assert [c["condition"] for c in summary["conditions"]] == ["gen1, 6 objects", "gen2, 5 objects"]
    papers = {s["label"]: s["stats"]["paper"]["success_pct"] for s in summary["conditions"][0]["series"]}
    assert papers == {"HLP, closed": None, "HLP, open": 94.0}  # the paper ran open loop only
    assert all(c["ratios"] == [] for c in summary["conditions"])
    markdown = summary_markdown(summary)
    assert "| gen1, 6 objects | HLP, open | 2 |" in markdown and "mean total times" not in markdown


def test_a_bars_value_label_stays_clear_of_the_papers_diamond_at_its_top(monkeypatch, tmp_path):
    """Ours 96 %, the paper's 93 %: the diamond sits near the bar's top, the value at half height."""
    from hlp_drake.experiments import plots

    def series(label: str, ours: float, paper: float) -> dict:
        stats = {"n": 100, "success_pct": ours, "success_ci95": [ours - 6, ours + 2]}
        return {"label": label, "stats": {**stats, "paper": {"success_pct": paper}}}

    summary = {
        "table": "Table III: Generalization II",
        "robot": "iiwa14",
        "conditions": [{"condition": "7 objects", "series": [series("HLP", 96, 93), series("STO", 91, 96)]}],
    }
    figures = []
    monkeypatch.setattr(plots, "save_png", lambda figure, path: figures.append(figure))
    plots.plot_success(summary, tmp_path / "success.png")
    (axes,) = figures[0].axes
    plots.plt.close(figures[0])
    labels = {text.get_text(): text.xy[1] for text in axes.texts}
    assert labels == {"96": 48.0, "91": 45.5}
    for value in (93, 96):  # the paper's diamonds, 45 or more points above either label
        assert all(abs(value - y) > 40 for y in labels.values())
