"""``python -m hlp_drake.segment``: see ``hlp_drake.commands.segment``."""

from hlp_drake.commands import run_command

if __name__ == "__main__":
    raise SystemExit(run_command("segment"))
