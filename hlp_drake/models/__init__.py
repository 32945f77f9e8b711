"""Model files (robot and scene) of the ``hlp_drake_models`` Drake package, and the robots it ships.

``SHIPPED_ROBOTS``: the robot descriptions in its ``robot`` folder (``NAME.yaml`` beside
``NAME.urdf``), the default first; a robot shipped later is its two files, no code.
"""

from __future__ import annotations

from pathlib import Path

DEFAULT_ROBOT = "mobile_ur5"
ROBOTS_FOLDER = Path(__file__).resolve().parent / "robot"
SHIPPED_ROBOTS = tuple(
    sorted((p.stem for p in ROBOTS_FOLDER.glob("*.yaml")), key=lambda name: (name != DEFAULT_ROBOT, name))
)
"""The shipped robots' names (``hlp_drake.systems.load_robot(NAME)``), the default first."""
