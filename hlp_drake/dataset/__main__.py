"""``python -m hlp_drake.dataset``: see ``hlp_drake.commands.dataset``."""

from hlp_drake.commands import run_command

if __name__ == "__main__":
    raise SystemExit(run_command("dataset"))
