"""The project's own Drake model package (``package://hlp_drake_models/...``); no remote packages."""

from __future__ import annotations

import os
from contextlib import contextmanager
from pathlib import Path

from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import MultibodyPlant

import hlp_drake.models
from hlp_drake.errors import InstallError, short

MODELS_PACKAGE = "hlp_drake_models"


def models_directory() -> Path:
    """The folder that holds ``package.xml`` and the robot and scene model files."""
    return Path(hlp_drake.models.__file__).resolve().parent


REINSTALL = (
    "reinstall hlp_drake (pip install --force-reinstall --no-deps hlp_drake; in a clone: git checkout models)"
)
"""The hint of a damaged or missing model package."""


def drake_reason(error: Exception, named: Path | None = None) -> str:
    """The first line of a Drake error, short (its parse errors run over many lines); the file
    ``named`` already names in the message is called by its name only (a deep install path would
    otherwise push the hint off the one-line message)."""
    lines = [line.strip() for line in str(error).splitlines() if line.strip()]
    first = lines[0] if lines else type(error).__name__
    if named is not None:
        first = first.replace(str(named), named.name)
    return short(first, 160)


def configure_parser(parser: Parser) -> Parser:
    """Register the project's model package with ``parser``'s package map and return the parser.

    Raises:
        InstallError: the package's ``package.xml`` is missing or cannot be read.
    """
    package_map = parser.package_map()
    if not package_map.Contains(MODELS_PACKAGE):
        xml = models_directory() / "package.xml"
        try:
            package_map.AddPackageXml(str(xml))
        except RuntimeError as error:
            raise InstallError(
                f"{xml}: the model package is missing or damaged ({drake_reason(error, xml)}); {REINSTALL}"
            ) from None
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
