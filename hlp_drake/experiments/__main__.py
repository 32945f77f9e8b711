"""``python -m hlp_drake.experiments``: see ``hlp_drake.experiments.cli``."""

from hlp_drake.cli import run_cli
from hlp_drake.experiments.cli import main

if __name__ == "__main__":
    raise SystemExit(run_cli(main))
