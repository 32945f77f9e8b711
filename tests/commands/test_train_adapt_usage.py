"""``python -m hlp_drake.train --adapt``'s usage errors (no dataset needed)."""

from __future__ import annotations

import pytest
from conftest import run_module


@pytest.mark.parametrize(
    ("args", "error"),
    [
        (["--base", "bundled"], "--base names the models --adapt starts from: give --adapt DEMOS too"),
        (
            ["--adapt", "demos", "--subjects", "sub_01"],
            "--adapt reads DEMOS and the base models, not --subjects",
        ),
        (["--adapt", "demos", "--preset", "svm"], "--adapt reads DEMOS and the base models, not --preset"),
    ],
)
def test_adapt_usage_errors_are_one_line(tmp_path, args, error):
    result = run_module("hlp_drake.train", *args, "--out", str(tmp_path / "models"))
    assert result.returncode == 2 and result.stdout == ""
    assert result.stderr == f"error: {error} (see python -m hlp_drake.train --help)\n"


def test_a_demos_path_that_is_a_file_is_refused(tmp_path):
    demos = tmp_path / "demos.csv"
    demos.write_text("trial,gap\n")
    result = run_module("hlp_drake.train", "--adapt", str(demos), "--out", str(tmp_path / "models"))
    assert result.returncode == 2 and result.stdout == ""
    assert result.stderr == (
        f"error: {demos}: not a folder (expected one person's VR logs: sub_XX/trial_results.csv and a "
        "sub_XX/TYYY/ folder per trial; or a person file, .yaml)\n"
    )
