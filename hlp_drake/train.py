"""``python -m hlp_drake.train``: see ``hlp_drake.commands.train``."""

from hlp_drake.commands import run_command

if __name__ == "__main__":
    raise SystemExit(run_command("train"))
