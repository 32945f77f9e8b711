"""``python -m hlp_drake.evaluate``: see ``hlp_drake.evaluation.cli``."""

from hlp_drake.cli import run_cli
from hlp_drake.evaluation.cli import main

if __name__ == "__main__":
    raise SystemExit(run_cli(main))
