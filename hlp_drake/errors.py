"""Errors that reach the user as a one-line message (no traceback)."""

from __future__ import annotations

MAX_PROBLEMS = 20
"""Problems an error lists; the rest are counted on one more line ("and N more problems")."""
MAX_LINE = 300
"""Characters of one problem line; a longer one is cut (the field it names comes first)."""


def short(text: str, limit: int = MAX_LINE) -> str:
    """``text`` on one line, at most ``limit`` characters (cut with "...")."""
    line = " ".join(str(text).split()) if ("\n" in text or "\r" in text) else str(text)
    return line if len(line) <= limit else line[: limit - 3] + "..."


class HlpError(Exception):
    """Base class of the errors a command-line user can cause and fix (bad file, bad path, ...).

    ``problems`` holds one message per problem, each one line of at most ``MAX_LINE`` characters,
    at most ``MAX_PROBLEMS`` of them and then "and N more problems"; ``count`` is how many there
    were in all; ``str(error)`` joins the lines with "; ". ``exit_status`` is the command's (2: bad
    input).
    """

    exit_status = 2

    def __init__(self, *problems: str) -> None:
        if not problems:
            raise ValueError("an HlpError needs at least one problem")
        self.count = len(problems)
        shown = [short(p) for p in problems[:MAX_PROBLEMS]]
        if self.count > MAX_PROBLEMS:
            more = self.count - MAX_PROBLEMS
            shown.append(f"and {more} more problem{'s' if more > 1 else ''}")
        self.problems: tuple[str, ...] = tuple(shown)
        super().__init__("; ".join(self.problems))


class FormerName(FutureWarning):
    """A setting read by its former name: it still works; the message names where it is now (the
    command line shows it as one ``note:`` line)."""


class SceneError(HlpError):
    """A scene file or Scene object is malformed or physically impossible."""


class DatasetError(HlpError):
    """The VR dataset cannot be found or read."""


class ModelError(HlpError):
    """A saved model file is missing, foreign, damaged or tampered with."""


class StorageError(HlpError):
    """An output could not be written during a run (a full disk, a folder that became unwritable):
    the run failed (exit 1), everything written before is intact and no file is half-written."""

    exit_status = 1


class InstallError(HlpError):
    """The installed package is incomplete or damaged (e.g. the robot model cannot be parsed), or
    the environment refuses something a command needs (e.g. Drake's network policy and MeshCat)."""
