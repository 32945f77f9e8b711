"""Studies: a grid of conditions run on seeded scenes, resumable, local or on dask; the paper's Tables II and III are the bundled gen1 and gen2.

    python -m hlp_drake.experiments {gen1,gen2,STUDY.yaml} [--scenes N] [--objects K ...] [--seed S]
        [--robot NAME|FILE ...] [--tables NAME|FILE] [--planner hlp|line ...] [--low-level NAME ...]
        [--execution open|closed ...] [--perception truth|camera ...] [--uncertainty [SEED]]
        [--workers N] [--executor local|dask] [--scheduler ADDRESS] [--config SCENARIO.yaml]
        [--fresh] [--quiet | --verbose] --out DIR

A study (hlp_drake.experiments.Study) names its scene generators, object counts, scenes and first
seed, and the axes of its grid: robots, initialisers, low-level planners, execution modes, perception
sources and model errors. gen1 (Table II) and gen2 (Table III) plan and execute every scene with both
initialisers (the human-like plan and the straight line) on the STO; the options replace the study's
settings (several values: one cell each). Scene i has seed S + i (for each generator and object
count). Writes DIR/results.csv (resumable: run the same command again after an interrupt), one row
per scene and cell, config.json (what the rows depend on), run.json (the run's settings, what it
ran, machine and software), summary.md/.json (the study's table beside the paper's numbers, and the
ratios of the initialisers' mean total times), success.png and times.png. Times are planning times
(plan + IK + low-level planning), without the simulated execution; run with --workers 1 for times
comparable to the paper's (parallel jobs share the cores). With --perception camera the planners plan
on the scene the world's cameras see (ScenePerception) while the simulation runs the true one.
"""

from __future__ import annotations

import argparse
import shlex
import sys
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

from hlp_drake.commands.parsing import (
    MAX_WORKERS,
    add_run_conditions,
    add_verbosity,
    drake_logging,
    integer,
    make_parser,
)
from hlp_drake.config.ranges import MAX_SEED, config_problems
from hlp_drake.errors import HlpError
from hlp_drake.experiments.study import EXECUTORS, MAX_SCENES, Study, bundled_studies, load_study
from hlp_drake.files.atomic import check_folder
from hlp_drake.scene.constants import MAX_GENERATED

if TYPE_CHECKING:
    from hlp_drake.experiments.runner import JobFunction, StudyResolver

PROG = "python -m hlp_drake.experiments"
OVERRIDES = {
    "scenes": "scenes",
    "objects": "objects",
    "seed": "seed",
    "robot": "robots",
    "planner": "initialisers",
    "low_level": "low_level",
    "execution": "execution",
    "perception": "perception",
    "world": "world",
    "tables": "tables",
}
"""The options that replace a study's settings: option -> ``Study`` field."""


def _parser() -> argparse.ArgumentParser:
    parser = make_parser(PROG, __doc__)
    parser.add_argument(
        "study",
        metavar="STUDY",
        help=f"a bundled study ({', '.join(bundled_studies())}: Tables II and III) or a study .yaml file",
    )
    parser.add_argument(
        "--scenes", type=integer(1, MAX_SCENES), metavar="N", help="scenes per condition (gen1, gen2: 100)"
    )
    parser.add_argument(
        "--objects",
        type=integer(1, MAX_GENERATED),
        nargs="+",
        metavar="K",
        help="object counts, one condition each (gen2: 5 7 9; gen1 ignores it: 6)",
    )
    parser.add_argument(
        "--seed",
        type=integer(0, MAX_SEED - MAX_SCENES),
        metavar="S",
        help="scene i has seed S + i (default 0)",
    )
    add_run_conditions(parser, several=True)
    parser.add_argument(
        "--tables",
        metavar="NAME|FILE",
        help="generate the tables within this robot's reach instead of --robot's (e.g. --robot "
        "mobile_ur5 --tables panda: the mobile UR5 on the Panda's scenes)",
    )
    parser.add_argument(
        "--workers", type=integer(1, MAX_WORKERS), metavar="N", help="jobs at a time (default: one per core)"
    )
    parser.add_argument(
        "--executor",
        choices=EXECUTORS,
        default="local",
        help="local (default): this process or a process pool; dask: a dask cluster",
    )
    parser.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        help="dask scheduler address (default: a LocalCluster of --workers processes)",
    )
    parser.add_argument(
        "--config",
        metavar="SCENARIO.yaml",
        help="scenario settings (see hlp_drake.systems.Scenario); each job has its own scene",
    )
    parser.add_argument("--fresh", action="store_true", help="discard DIR's earlier results and start over")
    add_verbosity(parser)
    parser.add_argument(
        "--out",
        required=True,
        metavar="DIR",
        help="output directory, made if missing (its parent must exist); resumes the run there",
    )
    return parser


def study_of(args: argparse.Namespace) -> Study:
    """The study ``args.study`` names, with the options given in place of its settings."""
    study = load_study(args.study)
    changes = {
        field: tuple(value) if isinstance(value, list) else value
        for option, field in OVERRIDES.items()
        if (value := getattr(args, option)) is not None
    }
    if args.uncertainty is not None:
        changes["model_error"] = (args.uncertainty,)
    if not changes:
        return study
    study = replace(study, **changes)
    problems = config_problems(study)  # the file's own settings passed: these are the options'
    if problems:
        raise HlpError(*(_as_option(problem) for problem in problems))
    return study


def _as_option(problem: str) -> str:
    """``problem`` of a ``Study`` field named after the option that set it."""
    options = {field: option for option, field in OVERRIDES.items()} | {"model_error": "uncertainty"}
    field = problem.split(":")[0].split(" ")[0]
    if field not in options:
        return problem
    return f"--{options[field].replace('_', '-')}{problem[len(field) :]}"


def main(
    argv: Sequence[str] | None = None,
    *,
    job: JobFunction | None = None,
    resolve: StudyResolver | None = None,
) -> int:
    """Run the study of ``argv``; ``job`` and ``resolve`` replace the real (scene, cell) job and the
    reading of the study's scenario (``hlp_drake.systems.execution.job``'s, which import Drake),
    e.g. in tests."""
    parser = _parser()
    args = parser.parse_args(argv)
    drake_logging(args.verbose)  # before Drake is first imported
    # Imported once the arguments are good: --help and a usage error need none of them.
    from hlp_drake.experiments.experiment import OUTPUTS, ExperimentSettings, run_experiment
    from hlp_drake.experiments.summary import summary_markdown

    check_folder(args.out, *OUTPUTS)  # a bad folder: exit 2, before the study is read

    study = study_of(args)
    config_yaml = None
    if args.config:
        from hlp_drake.systems.scenario import load_scenario

        config_yaml = load_scenario(args.config).yaml  # a robot model's relative path: beside the file
    settings = ExperimentSettings(
        study=study,
        workers=args.workers,
        executor=args.executor,
        scheduler=args.scheduler,
        config_yaml=config_yaml,
        scenario_file=args.config,
        fresh=args.fresh,
        progress=not args.quiet,
    )
    command = f"{parser.prog} {shlex.join(sys.argv[1:] if argv is None else argv)}"
    if job is None or resolve is None:
        from hlp_drake.systems.execution import job as drake_side

        job = job or drake_side.run_job
        resolve = resolve or drake_side.resolve_study
    summary = run_experiment(settings, args.out, job=job, resolve=resolve, command=command)
    print(summary_markdown(summary), end="")
    print(f"wrote {', '.join(str(Path(args.out) / name) for name in OUTPUTS)}")
    return 0
