"""Progress bars only on a terminal (in a file or a pipe their carriage returns would run into the
lines), and counts said in words."""

from __future__ import annotations

import sys
from typing import TextIO


def is_terminal(stream: TextIO | None) -> bool:
    """Whether ``stream`` is a terminal (where a progress bar can redraw itself)."""
    try:
        return stream is not None and stream.isatty()
    except (AttributeError, ValueError):  # no isatty, or closed
        return False


def counted(n: int, noun: str, plural: str | None = None) -> str:
    """``n`` and ``noun``, in the plural unless ``n`` is 1: ``1 obstacle``, ``6 obstacles``."""
    return f"{n} {noun if n == 1 else plural or noun + 's'}"


def bars_disabled(progress: bool, stream: TextIO | None = None) -> bool:
    """tqdm's ``disable``: no bar unless ``progress`` is wanted and ``stream`` (stderr by default) is a
    terminal."""
    return not (progress and is_terminal(sys.stderr if stream is None else stream))
