"""The paper's Generalization I and II experiments (Tables II and III), resumable, local or on dask.

    python -m hlp_drake.experiments {gen1,gen2} [--scenes 100] [--objects 5 7 9] [--seed S]
        [--workers N] [--executor local|dask] [--scheduler ADDRESS] [--config SCENARIO.yaml]
        [--perception truth|camera] [--execution open|closed] [--uncertainty [SEED]] [--fresh] [--quiet | --verbose]
        --out DIR

Every scene is planned and executed with both planners (HLP and STO's straight line); scene i has
seed S + i (gen2: for each object count). Writes DIR/results.csv (resumable: run the same command
again after an interrupt), config.json (what the rows depend on), run.json (the run's settings,
what it ran, machine and software), summary.md/.json (Table II or III beside the paper's numbers,
and the ratio of the planners' mean total times), success.png and times.png. Times are planning times (plan + IK + optimisation), without the
simulated execution; run with --workers 1 for times comparable to the paper's (parallel jobs share
the cores). With --perception camera both planners plan on the scene the world's cameras see
(ScenePerception) while the simulation runs the true one: Table III on perceived scenes.
"""

from __future__ import annotations

import argparse
import shlex
import sys
from collections.abc import Sequence
from pathlib import Path

from hlp_drake.commands.parsing import (
    MAX_SEED,
    MAX_WORKERS,
    add_conditions,
    add_perception,
    add_robot_option,
    add_verbosity,
    drake_logging,
    integer,
    make_parser,
)
from hlp_drake.experiments.executors import EXECUTORS
from hlp_drake.experiments.experiment import CONFIG, DERIVED, RESULTS, RUN, ExperimentSettings, run_experiment
from hlp_drake.experiments.runner import KINDS, JobFunction, ScenarioResolver
from hlp_drake.experiments.summary import summary_markdown
from hlp_drake.files.documents import read_document
from hlp_drake.scene.generators import MAX_GENERATED

PROG = "python -m hlp_drake.experiments"


def _parser() -> argparse.ArgumentParser:
    parser = make_parser(PROG, __doc__)
    parser.add_argument("kind", choices=KINDS, help="gen1: Table II; gen2: Table III")
    parser.add_argument(
        "--scenes",
        type=integer(1, 100_000),
        default=100,
        metavar="N",
        help="scenes per condition (default 100)",
    )
    parser.add_argument(
        "--objects",
        type=integer(1, MAX_GENERATED),
        nargs="+",
        default=[5, 7, 9],
        metavar="K",
        help="gen2's object counts, one condition each (default 5 7 9; gen1 ignores it: 6)",
    )
    parser.add_argument(
        "--seed",
        type=integer(0, MAX_SEED - 100_000),
        default=0,
        metavar="S",
        help="scene i has seed S + i (default 0)",
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
    add_perception(parser)
    add_robot_option(parser)
    parser.add_argument(
        "--tables",
        metavar="NAME|FILE",
        help="generate the tables within this robot's reach instead of --robot's (e.g. --robot "
        "mobile_ur5 --tables panda: the mobile UR5 on the Panda's scenes)",
    )
    add_conditions(parser)
    parser.add_argument("--fresh", action="store_true", help="discard DIR's earlier results and start over")
    add_verbosity(parser)
    parser.add_argument(
        "--out", required=True, metavar="DIR", help="output directory (resumes the run there)"
    )
    return parser


def main(
    argv: Sequence[str] | None = None,
    *,
    job: JobFunction | None = None,
    scenario: ScenarioResolver | None = None,
) -> int:
    """Run the experiment of ``argv``; ``job`` and ``scenario`` replace the real (scene, planner) job
    and scenario reading (``hlp_drake.systems.execution.job``'s, which import Drake), e.g. in tests."""
    parser = _parser()
    args = parser.parse_args(argv)
    drake_logging(args.verbose)  # before Drake is first imported
    config_yaml = None
    if args.config:
        config_yaml = read_document(args.config, missing="scenario file not found")
    if args.config or args.execution is not None or args.uncertainty is not None:
        from hlp_drake.systems.scenario import load_scenario, with_conditions

        loaded = load_scenario(args.config)  # a robot model's relative path: beside the file
        config_yaml = with_conditions(loaded, execution=args.execution, uncertainty=args.uncertainty).yaml
    settings = ExperimentSettings(
        kind=args.kind,
        scenes=args.scenes,
        objects=tuple(args.objects),
        seed=args.seed,
        workers=args.workers,
        executor=args.executor,
        scheduler=args.scheduler,
        config_yaml=config_yaml,
        perception=args.perception,
        robot=args.robot,
        tables=args.tables,
        scenario_file=args.config,
        fresh=args.fresh,
        progress=not args.quiet,
    )
    command = f"{parser.prog} {shlex.join(sys.argv[1:] if argv is None else argv)}"
    if job is None or scenario is None:
        from hlp_drake.systems.execution import job as drake_side

        job = job or drake_side.run_job
        scenario = scenario or drake_side.scenario_yamls
    summary = run_experiment(settings, args.out, job=job, scenario=scenario, command=command)
    print(summary_markdown(summary), end="")
    print(f"wrote {', '.join(str(Path(args.out) / name) for name in (RESULTS, CONFIG, RUN, *DERIVED))}")
    return 0
