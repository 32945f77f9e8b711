"""``python -m hlp_drake.train``: see ``hlp_drake.learners.cli``."""

from hlp_drake.cli import run_cli
from hlp_drake.learners.cli import main

if __name__ == "__main__":
    raise SystemExit(run_cli(main))
