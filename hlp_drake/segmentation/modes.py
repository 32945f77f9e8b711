"""The two segmentation/feature modes: ``fixed`` (what the paper says) and ``faithful`` (the released code).

``faithful`` reproduces the original MATLAB code's behaviour including its bugs B1-B6 and B9-B11
(reference notes section 8); ``fixed`` (the default) corrects them. Every place that differs checks
``is_faithful(mode)`` and names the bug it reproduces.
"""

from __future__ import annotations

from typing import Literal

from hlp_drake.errors import HlpError

Mode = Literal["fixed", "faithful"]
MODES: tuple[Mode, ...] = ("fixed", "faithful")
DEFAULT_MODE: Mode = "fixed"


def check_mode(mode: str) -> Mode:
    """Return ``mode`` if it is a known mode, else raise an HlpError naming the choices."""
    if mode not in MODES:
        raise HlpError(f"unknown mode {mode!r}; choose one of {', '.join(MODES)}")
    return mode  # type: ignore[return-value]


def is_faithful(mode: Mode) -> bool:
    return check_mode(mode) == "faithful"
