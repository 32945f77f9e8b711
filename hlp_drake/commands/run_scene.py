"""Plan a scene with the human-like planner (or the straight line), turn the plan into a motion with the STO and run it in Drake.

    python -m hlp_drake.run_scene [--scene FILE | --kind vr|gen1|gen2|unstructured --seed N [--objects K]]
        [--planner hlp|line] [--low-level sto] [--perception truth|camera] [--config SCENARIO.yaml]
        [--workers N] [--meshcat [--meshcat-wait SECONDS]] [--html FILE] [--contact-forces] [--execution open|closed]
        [--uncertainty [SEED]] [--models DIR [--models-sha256 HEX]] [--json FILE] [--quiet | --verbose]

With no arguments it runs the bundled default scene with the bundled models; --models DIR plans
with trained or adapted ones (python -m hlp_drake.train --out DIR, or --adapt), refused unless
their models.json has the SHA-256 --models-sha256 gives, when given. --planner picks the
initialiser (hlp: the human-like plan; line, also accepted as sto: the straight line of the paper's
baseline) and --low-level the planner that turns it into the robot's motion. With --perception camera
the initialiser, IK and low-level planner work on the scene the world's cameras see
(ScenePerception) while the simulation runs the true one; the plan names each perceived object by
the true one it was matched to, the perceived name beside, and the JSON's perception record compares
the two scenes. A header says what runs (the scene; the robot, initialiser, low-level planner,
execution mode, model error, perception source and scenario file), each stage is printed as it
happens (plan, IK, the optimiser's rollouts, the execution's simulated time), then a summary ending
in one verdict line: the paper's reach success (the target in the gripper's pre-grasp region, no
object off the table), the grasp beside it.

With --meshcat, MeshCat keeps serving the run after it ends, until Ctrl-C: a script that must
go on gives --meshcat-wait SECONDS (0: end at once; N: serve N s more, then end).

Exit status: 0 when the reach succeeded, whether or not the grasp then held (the grasp is reported,
not part of success); 1 when it failed (the verdict line says why); 2 on bad input; 130 when
interrupted.
"""

from __future__ import annotations

import contextlib
import json
import os
import sys
import time
from collections.abc import Sequence

from hlp_drake.commands.parsing import (
    MAX_WORKERS,
    add_run_conditions,
    add_verbosity,
    drake_logging,
    integer,
    make_parser,
    seconds,
)
from hlp_drake.config.ranges import MAX_SEED
from hlp_drake.config.what_ran import WhatRan
from hlp_drake.errors import InstallError
from hlp_drake.files.atomic import check_writable, write_text_atomic
from hlp_drake.runtime.terminal import counted
from hlp_drake.scene.constants import DEFAULT_SCENE_FILE, KINDS, MAX_GENERATED

DEFAULT_SCENE = DEFAULT_SCENE_FILE
PROG = "python -m hlp_drake.run_scene"
MAX_MESHCAT_WAIT = 7 * 24 * 3600.0
"""Longest --meshcat-wait, in seconds (a week)."""
INITIALISER_NAMES = {"hlp": "human-like", "line": "straight-line"}
"""The initialisers as the recording's heading names them."""


MODEL_VERDICTS = {None: "no motion planned", True: "accepted", False: "not accepted"}
"""The planner's own verdict in its model, as the verdict line says it."""


def model_verdict(result) -> str:
    """The low-level planner's verdict in its own model, beside the world's (a false accept named)."""
    said = MODEL_VERDICTS[result.model_success]
    return f"{said}: a false accept" if result.false_accept else said


def verdict(result) -> str:
    """The verdict line: whether the reach succeeded in the world that judged it (the paper's success,
    which sets the exit status), the planner's own verdict in its model, and whether the grasp held."""
    grasp = {None: "not attempted", True: "held", False: "did not hold"}[result.grasp_held]
    if result.grasp_failure is not None:
        grasp = f"did not hold ({result.grasp_failure})"
    world = f"in the {result.world} world"
    reach = (
        f"reach success {world} (the paper's criterion, exit status 0)"
        if result.success
        else f"reach failure {world}: {result.failure_reason} (exit status 1)"
    )
    return (
        f"verdict: {reach}; the planner's model: {model_verdict(result)}; grasp {grasp} "
        "(reported, not part of success)"
    )


def exit_status(result) -> int:
    """0 when the reach succeeded (the paper's success), whatever the grasp; 1 when it failed."""
    return 0 if result.success else 1


def recording_title(result, ran: WhatRan) -> str:
    """The recording's heading: the scene, the initialiser, the low-level planner and perception, and
    the verdict in short."""
    reach = "reach success" if result.success else f"reach failure: {result.failure_reason}"
    reach += f" in the {result.world} world (the model: {model_verdict(result)})"
    held = {None: "", True: ", grasp held", False: ", grasp did not hold"}[result.grasp_held]
    planners = " and ".join(INITIALISER_NAMES.get(p, p) for p in ran.initials)
    planners += f" planner with the {' and '.join(ran.low_levels)} low-level planner"
    seen = "on the depth camera's view" if "camera" in ran.perceptions else "on the true scene"
    return f"scene {result.scene.name}, {planners} {seen}: {reach}{held}"


def _planned(result) -> str:
    """What a low-level planner that does not roll out did (its time, and its iterations and fallback
    where it has them), or that none ran."""
    record = result.optimisation
    if not record:
        return "not optimised"
    said = [counted(result.iterations, "iteration")] if result.iterations else []
    said += [record["fallback"]] if record.get("fallback") else []
    detail = f" ({'; '.join(said)})" if said else ""
    return f"{result.low_level} {result.timings['optimise_s']:.2f} s{detail}"


def summary(result) -> str:
    """The run's summary: timings, the objects moved and dropped, the verdict (what ran is the
    header's ``run:`` line, printed before the run)."""
    t = result.timings
    start = (result.optimisation or {}).get("start", 0)
    alternative = f", from the planner's alternative {start}" if start else ""
    optimiser = (
        f"optimise {t['optimise_s']:.1f} s ({counted(result.iterations, 'iteration')}, "
        f"{counted(result.rollouts, 'rollout')}{alternative})"
        if result.rollouts
        else _planned(result)
    )
    verified = (result.optimisation or {}).get("verifications", 0)
    if verified:
        displaced = result.optimisation.get("displaced_checks", 0)
        optimiser += (
            f", {verified} checked before accepting"
            + (f" and in {displaced} displaced worlds" if displaced else "")
            + f" ({result.optimisation['rejected']} rejected, {result.optimisation.get('verify_s', 0.0):.1f} s of it)"
        )
    loop = result.closed_loop
    if loop:
        optimiser += (
            f"; closed loop: {counted(loop['replans'], 're-optimisation')}, "
            f"{counted(loop['rollouts'], 'rollout')}, {counted(loop['on_track'], 'period')} on track"
        )
    lines = [
        (
            f"timings: plan {t['plan_s']:.3f} s, IK {t['ik_s']:.2f} s, {optimiser}, execute {t['execute_s']:.1f} s "
            f"({result.simulated_s:.1f} s simulated), total {t['total_s']:.1f} s"
        ),
        f"objects moved: {', '.join(result.objects_moved) or 'none'}; dropped: {', '.join(result.objects_dropped) or 'none'}",
        verdict(result),
    ]
    return "\n".join(lines)


def _parser():
    parser = make_parser(PROG, __doc__)
    source = parser.add_mutually_exclusive_group()
    source.add_argument(
        "--scene", metavar="FILE", help="a scene file (YAML or JSON); default: the bundled default scene"
    )
    source.add_argument("--kind", choices=KINDS, help="generate a scene of this kind (with --seed)")
    parser.add_argument(
        "--seed", type=integer(0, MAX_SEED), help="seed of the generated scene (with --kind; default 0)"
    )
    parser.add_argument(
        "--objects",
        type=integer(1, MAX_GENERATED),
        metavar="K",
        help="number of obstacles of the generated scene (with --kind gen2 or unstructured)",
    )
    add_run_conditions(parser)
    parser.add_argument(
        "--config",
        metavar="SCENARIO.yaml",
        help="scenario settings (see hlp_drake.systems.Scenario); --scene or --kind replace its scene",
    )
    parser.add_argument(
        "--workers",
        type=integer(1, MAX_WORKERS),
        metavar="N",
        help="rollout processes of a low-level planner that rolls out (default: the scenario's, 2)",
    )
    parser.add_argument(
        "--meshcat",
        action="store_true",
        help="show the run live in MeshCat (prints the URL); MeshCat keeps serving after the run until "
        "Ctrl-C unless --meshcat-wait says otherwise",
    )
    parser.add_argument(
        "--meshcat-wait",
        type=seconds(MAX_MESHCAT_WAIT),
        metavar="SECONDS",
        help="with --meshcat: serve the finished run this long, then end (0: end at once; default: "
        "until Ctrl-C)",
    )
    parser.add_argument("--html", metavar="FILE", help="write a self-contained MeshCat recording of the run")
    parser.add_argument("--contact-forces", action="store_true", help="draw the contact forces in MeshCat")
    parser.add_argument(
        "--models",
        metavar="DIR",
        help="the decision models (models.json and models.npz; default: the scenario's, else the bundled)",
    )
    parser.add_argument(
        "--models-sha256",
        metavar="HEX",
        help="with --models: the SHA-256 of the trusted models.json (other files are refused)",
    )
    parser.add_argument("--json", metavar="FILE", help="write the result as JSON")
    add_verbosity(parser)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    started = time.perf_counter()
    parser = _parser()
    args = parser.parse_args(argv)
    if args.kind is None and (args.seed is not None or args.objects is not None):
        parser.error("--seed and --objects describe a generated scene: give its --kind too")
    if args.models_sha256 is not None and args.models is None:
        parser.error("--models-sha256 pins the models of --models DIR: give --models too")
    if args.meshcat_wait is not None and not args.meshcat:
        parser.error("--meshcat-wait is how long --meshcat serves after the run: give --meshcat too")
    check_writable(args.json, args.html)
    scenario = _scenario(args)  # every input checked before the first line is printed
    from hlp_drake.systems.execution.result import what_ran

    ran = what_ran(scenario, args.config)
    _print(f"scene {scenario.scene.name}: {counted(len(scenario.scene.obstacles), 'obstacle')}")
    _print(f"run: {ran.line()}")
    result, meshcat = _run(scenario, args, started)
    print(summary(result))
    _write(args, scenario, result, ran, meshcat)
    if args.meshcat:
        serve(args.meshcat_wait, time.perf_counter() - started)
    return exit_status(result)


def serve(wait: float | None, spent: float, sleep=time.sleep) -> None:
    """Keep MeshCat serving the finished run ``wait`` seconds (None: until Ctrl-C; 0: not at all),
    after saying so; Ctrl-C ends the wait (the run's exit status stands)."""
    done = f"done in {spent:.1f} s"
    if wait == 0:
        print(f"{done}; MeshCat stops now (--meshcat-wait 0)", flush=True)
        return
    if wait is None:
        print(
            f"{done}; MeshCat keeps serving until you press Ctrl-C (or give --meshcat-wait SECONDS)",
            flush=True,
        )
    else:
        print(f"{done}; MeshCat keeps serving {wait:g} s more (Ctrl-C ends it sooner)", flush=True)
    try:
        if wait is None:
            while True:
                sleep(1.0)
        else:
            sleep(wait)
    except KeyboardInterrupt:
        pass


def _scenario(args):
    """The run's scenario: ``--config`` (the defaults without it) under the flags' ``Conditions``, on
    ``--scene``, a scene generated for the robot (``--kind``), the bundled default scene (scaled to a
    fixed robot's reach) or the scenario's own; nothing is printed (a bad input is refused before any
    output)."""
    from hlp_drake.scene.generators import generate_scene  # numpy and shapely: once the arguments are good
    from hlp_drake.scene.io import load_scene

    scene = None
    if args.kind is None and (args.scene is not None or args.config is None):
        scene = load_scene(args.scene or DEFAULT_SCENE)
    drake_logging(args.verbose)  # Drake is imported from here on
    from hlp_drake.systems.conditions import Conditions
    from hlp_drake.systems.scenario import load_scenario
    from hlp_drake.systems.world.robot_description import load_robot

    base = load_scenario(args.config)
    if args.kind is not None:  # generated for the robot: a fixed one's table within its reach
        robot = base.robot if args.robot is None else load_robot(args.robot)
        scene = generate_scene(args.kind, args.seed or 0, args.objects, robot.workspace)
    conditions = Conditions(
        robot=args.robot,
        initial=args.planner,
        low_level=args.low_level,
        execution=args.execution,
        uncertainty=args.uncertainty,
        perception=args.perception,
        world=args.world,
        workers=args.workers,
    )
    scenario = conditions.applied(base, scene=scene)
    if args.models is not None:
        from dataclasses import replace

        from hlp_drake.systems.planning.diagram import scenario_models

        planner = replace(scenario.planner, models=args.models, models_sha256=args.models_sha256 or "")
        scenario = replace(scenario, planner=planner)
        scenario_models(scenario)  # a missing, damaged or unpinned model file: refused before any output
    return scenario


def _write(args, scenario, result, ran, meshcat) -> None:
    """Write the recording (``--html``) and the result (``--json``)."""
    if args.html:
        from hlp_drake.systems.execution.meshcat_view import with_legend

        perceived = scenario.perception.source == "camera"
        page = with_legend(meshcat.StaticHtml(), perceived=perceived, title=recording_title(result, ran))
        write_text_atomic(args.html, page)
        print(f"wrote {args.html}")
    if args.json:
        write_text_atomic(args.json, json.dumps({**ran.to_dict(), **result.to_dict()}, indent=2) + "\n")
        print(f"wrote {args.json}")


def _print(line: str) -> None:
    print(line, flush=True)


def _meshcat():
    """A MeshCat server on localhost.

    Raises:
        InstallError: Drake's network policy (``DRAKE_ALLOW_NETWORK``) refuses MeshCat, or the
            server cannot start.
    """
    from pydrake.geometry import Meshcat, MeshcatParams

    try:
        return Meshcat(MeshcatParams(host="localhost"))
    except RuntimeError as error:
        policy = os.environ.get("DRAKE_ALLOW_NETWORK")
        if policy is not None and "meshcat" not in policy.split(":"):
            raise InstallError(
                f"--meshcat and --html need MeshCat, which DRAKE_ALLOW_NETWORK={policy} refuses; "
                "allow it with DRAKE_ALLOW_NETWORK=meshcat (or unset the variable)"
            ) from None
        raise InstallError(f"cannot start MeshCat: {' '.join(str(error).split())}") from None


def _run(scenario, args, started: float):
    """Plan and execute ``scenario`` (on a rollout pool of its own if its low-level planner rolls
    out), the stages printed as they come."""
    from hlp_drake.commands.progress import ProgressListener
    from hlp_drake.systems.conditions import rollout_workers
    from hlp_drake.systems.execution.run import plan_and_execute
    from hlp_drake.systems.low_level.sto.pool import RolloutPool

    meshcat = _meshcat() if args.meshcat or args.html else None
    if args.meshcat:
        _print(f"MeshCat: {meshcat.web_url()}")
    listener = ProgressListener(quiet=args.quiet, stream=sys.stderr)
    workers = rollout_workers(scenario)
    if workers is not None and workers > 1:
        _print(f"rollout workers: {workers}, started when a batch of rollouts needs them")
    pool = (
        contextlib.nullcontext()
        if workers is None
        else RolloutPool(workers, on_rollout=listener.rollout, on_warning=listener.warning)
    )
    with contextlib.closing(listener), pool:
        result = plan_and_execute(
            scenario,
            pool=pool if workers is not None else None,
            meshcat=meshcat,
            contact_forces=args.contact_forces,
            listener=listener,
        )
    return result, meshcat
