"""The project's own Drake model package (``package://hlp_drake_models/...``); no remote packages."""

from __future__ import annotations

from pathlib import Path

from pydrake.multibody.parsing import Parser

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
