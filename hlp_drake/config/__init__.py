"""Typed settings: YAML text to frozen dataclasses (``typed_yaml``), the ranges of their fields
(``ranges``), and what a run ran (``what_ran``)."""
