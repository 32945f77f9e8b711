"""``python -m hlp_drake.segment``: see ``hlp_drake.segmentation.cli``."""

from hlp_drake.cli import run_cli
from hlp_drake.segmentation.cli import main

if __name__ == "__main__":
    raise SystemExit(run_cli(main))
