"""``python -m hlp_drake.scene {generate,show,validate}``: make, draw and check scene files."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence

from hlp_drake.cli import run_cli
from hlp_drake.scene.generators import KINDS, generate_scene
from hlp_drake.scene.io import load_scene, save_scene
from hlp_drake.scene.rows import find_rows


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="python -m hlp_drake.scene", description=__doc__)
    commands = parser.add_subparsers(dest="command", required=True)
    generate = commands.add_parser("generate", help="write a seeded random scene")
    generate.add_argument("--kind", choices=KINDS, required=True)
    generate.add_argument("--objects", type=int, help="number of obstacles (gen2, unstructured)")
    generate.add_argument("--seed", type=int, required=True)
    generate.add_argument("--out", required=True, help="output file, .yaml or .json")
    show = commands.add_parser("show", help="draw a scene file top-down")
    show.add_argument("file")
    show.add_argument("--png", required=True, help="output PNG")
    validate = commands.add_parser("validate", help="check a scene file")
    validate.add_argument("file")
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    if args.command == "generate":
        scene = generate_scene(args.kind, args.seed, args.objects)
        save_scene(scene, args.out)
        print(f"wrote {args.out}: {scene.name}, {len(scene.obstacles)} obstacles")
    elif args.command == "show":
        from hlp_drake.scene.plot import save_scene_png

        save_scene_png(load_scene(args.file), args.png)
        print(f"wrote {args.png}")
    else:
        scene = load_scene(args.file)
        rows = find_rows(scene)
        print(f"{args.file}: valid ({len(scene.obstacles)} obstacles in {len(rows)} rows)")
    return 0


if __name__ == "__main__":
    sys.exit(run_cli(main))
