"""What went wrong when a Drake simulation failed, in one line (``simulation_failure``)."""

from __future__ import annotations


def simulation_failure(error: BaseException) -> str:
    """One line on a Drake simulation failure: a ``RuntimeError``'s first line, or one of Drake's
    internal checks failing (pydrake raises those as ``SystemExit("Failure at ...")``; a state turned
    non-finite, the contact solver having diverged, is said so). Any other ``SystemExit`` is raised
    again."""
    if isinstance(error, SystemExit) and not str(error).startswith("Failure at"):
        raise error
    line = str(error).splitlines()[0]
    if "AllFinite" in line:
        return "the simulation diverged (the state turned non-finite)"
    return line


__all__ = ["simulation_failure"]
