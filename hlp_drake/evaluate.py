"""``python -m hlp_drake.evaluate``: see ``hlp_drake.commands.evaluate``."""

from hlp_drake.commands import run_command

if __name__ == "__main__":
    raise SystemExit(run_command("evaluate"))
