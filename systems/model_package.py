"""The project's own Drake model package (``package://hlp_drake_models/...``); no remote packages."""

from __future__ import annotations

import os
from contextlib import contextmanager
from pathlib import Path

from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import MultibodyPlant

import hlp_drake.models

MODELS_PACKAGE = "hlp_drake_models"


def models_directory() -> Path:
    """The folder that holds ``package.xml`` and the robot and scene model files."""
    return Path(hlp_drake.models.__file__).resolve().parent


def configure_parser(parser: Parser) -> Parser:
    """Register the project's model package with ``parser``'s package map and return the parser."""
    package_map = parser.package_map()
    if not package_map.Contains(MODELS_PACKAGE):
        package_map.AddPackageXml(str(models_directory() / "package.xml"))
    return parser


@contextmanager
def _package_map_network_allowed():
    """Let Drake's default PackageMap *register* its remote ``drake_models`` package.

    Under ``DRAKE_ALLOW_NETWORK`` without ``package_map`` (e.g. ``none`` or ``meshcat``), Drake
    refuses to construct a Parser unless ``drake_models`` is already downloaded, although
    registering it downloads nothing (only resolving a ``package://drake_models/...`` URL would).
    Our models never refer to it, so the restriction is lifted for the construction only.
    """
    policy = os.environ.get("DRAKE_ALLOW_NETWORK")
    if policy is None or "package_map" in policy.split(":"):
        yield
        return
    os.environ["DRAKE_ALLOW_NETWORK"] = "package_map"
    try:
        yield
    finally:
        os.environ["DRAKE_ALLOW_NETWORK"] = policy


def new_parser(plant: MultibodyPlant) -> Parser:
    """A Parser for ``plant`` with the project's package registered, under any network policy."""
    with _package_map_network_allowed():
        parser = Parser(plant)
    return configure_parser(parser)
