"""Errors that reach the user as a one-line message (no traceback)."""

from __future__ import annotations


class HlpError(Exception):
    """Base class of the errors a command-line user can cause and fix (bad file, bad path, ...).

    ``problems`` holds one message per problem; ``str(error)`` joins them with "; ".
    """

    def __init__(self, *problems: str) -> None:
        if not problems:
            raise ValueError("an HlpError needs at least one problem")
        self.problems: tuple[str, ...] = tuple(problems)
        super().__init__("; ".join(self.problems))


class SceneError(HlpError):
    """A scene file or Scene object is malformed or physically impossible."""


class DatasetError(HlpError):
    """The VR dataset cannot be found or read."""


class ModelError(HlpError):
    """A saved model file is missing, foreign, damaged or tampered with."""
