"""``python -m hlp_drake.scene``: see ``hlp_drake.commands.scene``."""

from hlp_drake.commands import run_command

if __name__ == "__main__":
    raise SystemExit(run_command("scene"))
