"""Make, draw and check scene files: python -m hlp_drake.scene {generate,show,validate}.

python -m hlp_drake.scene generate --kind vr|gen1|gen2|unstructured --seed N [--objects K] --out FILE
python -m hlp_drake.scene show FILE --png OUT.png [--plan]
python -m hlp_drake.scene validate FILE

Each takes --robot NAME|FILE and --config SCENARIO.yaml (the scenario's robot; --robot replaces it):
generate fits a fixed robot's table within its reach, show --plan draws that robot's plan with the
scenario's push margins, validate also checks the scene against the scenario (e.g. the obstacles a
simulated world takes). --quiet leaves out Drake's INFO lines, --verbose shows them.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

from hlp_drake.commands.parsing import add_robot_option, add_verbosity, drake_logging, integer, make_parser
from hlp_drake.config.ranges import MAX_SEED
from hlp_drake.files.atomic import check_writable
from hlp_drake.runtime.terminal import counted
from hlp_drake.scene.generators import KINDS, MAX_GENERATED, generate_scene
from hlp_drake.scene.io import load_scene, save_scene
from hlp_drake.scene.rows import find_rows

if TYPE_CHECKING:
    from hlp_drake.scene.model import Scene
    from hlp_drake.systems.scenario import Scenario
    from hlp_drake.systems.world.robot_description import RobotDescription


def _common(parser) -> None:
    """The options every subcommand takes: ``--robot``, ``--config``, ``--quiet`` or ``--verbose``."""
    add_robot_option(parser)
    parser.add_argument(
        "--config",
        metavar="SCENARIO.yaml",
        help="scenario settings (see hlp_drake.systems.Scenario): its robot, unless --robot, and its "
        "push margins (show --plan)",
    )
    add_verbosity(parser)


def _parser():
    parser = make_parser("python -m hlp_drake.scene", __doc__)
    commands = parser.add_subparsers(dest="command", required=True)
    generate = commands.add_parser("generate", help="write a seeded random scene")
    generate.add_argument("--kind", choices=KINDS, required=True)
    generate.add_argument(
        "--objects", type=integer(1, MAX_GENERATED), help="number of obstacles (gen2, unstructured)"
    )
    generate.add_argument("--seed", type=integer(0, MAX_SEED), required=True)
    generate.add_argument("--out", required=True, help="output file, .yaml or .json")
    _common(generate)
    show = commands.add_parser("show", help="draw a scene file top-down")
    show.add_argument("file")
    show.add_argument("--png", required=True, help="output PNG")
    show.add_argument(
        "--plan",
        action="store_true",
        help="draw the human-like plan (bundled models) and the pushing robot's plan over it",
    )
    _common(show)
    validate = commands.add_parser("validate", help="check a scene file")
    validate.add_argument("file")
    _common(validate)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    check_writable(getattr(args, "out", None), getattr(args, "png", None))  # bad paths: exit 2, now
    scenario = _scenario(args.config, args.verbose)
    if args.command == "generate":
        robot = _robot(args.robot, scenario, args.verbose)
        workspace = None if robot is None else robot.workspace  # a fixed robot's tables within its reach
        scene = generate_scene(args.kind, args.seed, args.objects, workspace)
        save_scene(scene, args.out)
        print(f"wrote {args.out}: {scene.name}, {counted(len(scene.obstacles), 'obstacle')}")
    elif args.command == "show":
        from hlp_drake.scene.plot import save_scene_png

        scene = load_scene(args.file)
        robot = _robot(args.robot, scenario, args.verbose)  # checked with or without --plan
        plans = _plans(scene, robot, scenario) if args.plan else {}
        save_scene_png(scene, args.png, plans=plans)
        for label, plan in plans.items():
            print(f"{label}: {' -> '.join(k.action for k in plan.keypoints) or plan.reason}")
        print(f"wrote {args.png}")
    else:
        scene = load_scene(args.file)
        robot = _robot(args.robot, scenario, args.verbose)
        if scenario is not None or robot is not None:  # the scene in the scenario: its checks too
            from dataclasses import replace

            from hlp_drake.systems.scenario import Scenario

            base = scenario or Scenario()
            replace(base, scene=scene, robot=robot or base.robot)
        rows = find_rows(scene)
        print(
            f"{args.file}: valid ({counted(len(scene.obstacles), 'obstacle')} in {counted(len(rows), 'row')})"
        )
    return 0


def _scenario(config: str | None, verbose: bool) -> Scenario | None:
    """The scenario ``--config`` names (imports Drake), None without it."""
    if config is None:
        return None
    drake_logging(verbose)
    from hlp_drake.systems.scenario import load_scenario

    return load_scenario(config)


def _robot(name_or_file: str | None, scenario: Scenario | None, verbose: bool) -> RobotDescription | None:
    """The robot description ``--robot`` names, else the scenario's (imports Drake); None without
    either."""
    if name_or_file is None:
        return None if scenario is None else scenario.robot
    drake_logging(verbose)
    from hlp_drake.systems.world.robot_description import load_robot

    return load_robot(name_or_file)


def _plans(scene: Scene, robot: RobotDescription | None, scenario: Scenario | None) -> dict:
    """The human-like plan of ``scene`` and ``robot``'s plan of it (the mobile UR5's if None) with the
    scenario's push margins (the defaults' if None; imports Drake)."""
    from hlp_drake.learners.bundled import default_models
    from hlp_drake.planner import plan
    from hlp_drake.systems.planning.transfer import gripper_geometry
    from hlp_drake.systems.scenario import Scenario
    from hlp_drake.transfer.push import robot_plan
    from hlp_drake.transfer.rules import push_rules

    human = plan(scene, default_models())
    geometry = gripper_geometry() if robot is None else gripper_geometry(robot)
    scenario = scenario or Scenario()
    rules = push_rules(scenario.transfer, geometry, closed=scenario.motion.closed_among_obstacles)
    return {
        "human plan": human,
        "robot plan": robot_plan(human, scene, rules),
    }
