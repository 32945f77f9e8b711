"""Drake blocks of hlp_drake (imported as ``hlp_drake.systems``) and the model package they load."""

from hlp_drake.systems.model_package import MODELS_PACKAGE, configure_parser, models_directory

__all__ = ["MODELS_PACKAGE", "configure_parser", "models_directory"]
