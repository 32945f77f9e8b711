"""Fuzzing an experiment's run folder: a damaged one resumes with every row or is refused as it was."""

from __future__ import annotations

import functools
import json
import tempfile
from pathlib import Path

import pytest
from fuzz_support import PROFILES, STATS, check_error, flip_bytes, junk, run
from hypothesis import strategies as st

from hlp_drake.errors import HlpError


def _cheap_job(job):
    """A finished job's row without planning (the resume logic is what is fuzzed)."""
    from hlp_drake.experiments import make_row

    return make_row(
        job,
        success=job.seed % 2 == 0,
        failure_reason=None if job.seed % 2 == 0 else "the target is out of reach",
        plan_s=0.01,
        ik_s=0.1,
        optimise_s=1.0,
        verify_s=0.5,
        execute_s=2.0,
        rollouts=8,
        iterations=1,
        objects_moved=1,
        objects_dropped=0,
    )


def _run(out) -> None:
    """The cheap experiment (gen1 seeds 10 and 11, both initialisers) in ``out``, in this process."""
    from job_support import run_experiment, settings

    run_experiment(settings(scenes=2), out, job=_cheap_job)


@functools.cache
def _run_folder() -> dict[str, bytes]:
    """The records of a finished (cheap) experiment: results.csv, run.json, config.json."""
    with tempfile.TemporaryDirectory() as folder:
        _run(folder)
        return {
            name: (Path(folder) / name).read_bytes() for name in ("results.csv", "run.json", "config.json")
        }


@st.composite
def damaged_run_folder(draw) -> dict[str, bytes]:
    """A finished experiment folder's records, one damaged: bytes flipped or cut, a field of a row
    or a record replaced by junk."""
    files = _run_folder()
    name = draw(st.sampled_from(sorted(files)))
    data = files[name]
    how = draw(st.sampled_from(["bytes", "truncate", "field"]))
    if how == "bytes":
        data = flip_bytes(draw, data)
    elif how == "truncate":
        data = data[: draw(st.integers(0, len(data) - 1))]
    elif name == "results.csv":
        lines = data.decode().splitlines()
        row = draw(st.integers(1, len(lines) - 1))
        fields = lines[row].split(",")
        fields[draw(st.integers(0, len(fields) - 1))] = str(draw(junk)).replace("\n", " ")
        data = ("\n".join([*lines[:row], ",".join(fields), *lines[row + 1 :]]) + "\n").encode()
    else:
        record = json.loads(data)
        record[draw(st.sampled_from(sorted(record)))] = draw(junk)
        data = json.dumps(record).encode()
    return {**files, name: bytes(data)}


def _check_resume(files: dict[str, bytes]) -> None:
    from hlp_drake.experiments.results import COLUMNS, read_results

    STATS["run folders damaged"] += 1
    with tempfile.TemporaryDirectory() as folder:
        out = Path(folder)
        for name, data in files.items():
            (out / name).write_bytes(data)
        try:
            _run(out)
        except HlpError as error:
            check_error(error)
            assert {name: (out / name).read_bytes() for name in files} == files  # left as it was
            STATS["run folders refused"] += 1
            return
        rows = read_results(out / "results.csv", ("gen1",))  # resumed: every job's row, well-formed
        assert sorted((r["scene"], r["planner"]) for r in rows) == [
            (f"gen1-{seed}", planner) for seed in (10, 11) for planner in ("hlp", "sto")
        ]
        assert all(list(r) == list(COLUMNS) for r in rows)
        STATS["run folders resumed"] += 1


@pytest.mark.parametrize("profile", PROFILES)
def test_damaged_run_folders_resume_or_are_refused_as_they_were(profile):
    run(profile, (40, 400), damaged_run_folder(), _check_resume)
