"""``python -m hlp_drake.experiments``: see ``hlp_drake.commands.experiments``."""

from hlp_drake.commands import run_command

if __name__ == "__main__":
    raise SystemExit(run_command("experiments"))
