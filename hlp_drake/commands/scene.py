"""Make, draw and check scene files: python -m hlp_drake.scene {generate,show,validate}.

python -m hlp_drake.scene generate --kind vr|gen1|gen2|unstructured --seed N [--objects K] --out FILE
python -m hlp_drake.scene show FILE --png OUT.png [--plan [--robot NAME|FILE]]
python -m hlp_drake.scene validate FILE
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

from hlp_drake.commands.parsing import add_robot_option, integer, make_parser
from hlp_drake.config.ranges import MAX_SEED
from hlp_drake.files.atomic import check_writable
from hlp_drake.runtime.terminal import counted
from hlp_drake.scene.generators import KINDS, MAX_GENERATED, generate_scene
from hlp_drake.scene.io import load_scene, save_scene
from hlp_drake.scene.rows import find_rows

if TYPE_CHECKING:
    from hlp_drake.scene.model import Scene
    from hlp_drake.systems.world.robot_description import RobotDescription


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
    add_robot_option(generate)
    show = commands.add_parser("show", help="draw a scene file top-down")
    show.add_argument("file")
    show.add_argument("--png", required=True, help="output PNG")
    show.add_argument(
        "--plan",
        action="store_true",
        help="draw the human-like plan (bundled models) and the pushing robot's plan over it",
    )
    add_robot_option(show)
    validate = commands.add_parser("validate", help="check a scene file")
    validate.add_argument("file")
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    check_writable(getattr(args, "out", None), getattr(args, "png", None))  # bad paths: exit 2, now
    if args.command == "generate":
        robot = _robot(args.robot)
        workspace = None if robot is None else robot.workspace  # a fixed robot's tables within its reach
        scene = generate_scene(args.kind, args.seed, args.objects, workspace)
        save_scene(scene, args.out)
        print(f"wrote {args.out}: {scene.name}, {counted(len(scene.obstacles), 'obstacle')}")
    elif args.command == "show":
        from hlp_drake.scene.plot import save_scene_png

        scene = load_scene(args.file)
        robot = _robot(args.robot)  # checked with or without --plan
        plans = _plans(scene, robot) if args.plan else {}
        save_scene_png(scene, args.png, plans=plans)
        for label, plan in plans.items():
            print(f"{label}: {' -> '.join(k.action for k in plan.keypoints) or plan.reason}")
        print(f"wrote {args.png}")
    else:
        scene = load_scene(args.file)
        rows = find_rows(scene)
        print(
            f"{args.file}: valid ({counted(len(scene.obstacles), 'obstacle')} in {counted(len(rows), 'row')})"
        )
    return 0


def _robot(name_or_file: str | None) -> RobotDescription | None:
    """The robot description ``--robot`` names (imports Drake), None without it."""
    if name_or_file is None:
        return None
    from hlp_drake.systems.world.robot_description import load_robot

    return load_robot(name_or_file)


def _plans(scene: Scene, robot: RobotDescription | None) -> dict:
    """The human-like plan of ``scene`` and ``robot``'s plan of it (the mobile UR5's if None; imports
    Drake)."""
    from hlp_drake.learners.bundled import default_models
    from hlp_drake.planner import plan
    from hlp_drake.systems.planning.transfer import gripper_geometry
    from hlp_drake.systems.scenario import Scenario
    from hlp_drake.transfer.push import robot_plan
    from hlp_drake.transfer.rules import push_rules

    human = plan(scene, default_models())
    geometry = gripper_geometry() if robot is None else gripper_geometry(robot)
    return {
        "human plan": human,
        "robot plan": robot_plan(human, scene, push_rules(Scenario().transfer, geometry)),
    }
