"""``python -m hlp_drake.run_scene``: see ``hlp_drake.commands.run_scene``."""

from hlp_drake.commands import run_command

if __name__ == "__main__":
    raise SystemExit(run_command("run-scene"))
