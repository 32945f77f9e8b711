"""The paper's Tables II and III (our notes of them), shown beside a study's figures where a series
is one of the paper's: the human-like or the straight-line start on the STO (``planner`` ``hlp`` or
``sto``) in Generalization I or II."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class PaperFigures:
    """One planner's figures in the paper (None: not reported, or not in our notes)."""

    success_pct: float | None = None
    init_s: float | None = None
    optimise_s: float | None = None
    total_s: float | None = None


# Paper Table II (Gen I): success and total time; the init times are total - optimisation.
# Table III (Gen II): success only; its times are not in our notes.
PAPER: dict[tuple[str, int | None], dict[str, PaperFigures]] = {
    ("gen1", None): {
        "hlp": PaperFigures(94.0, round(1.56 - 0.97, 2), 0.97, 1.56),
        "sto": PaperFigures(84.0, round(17.88 - 17.84, 2), 17.84, 17.88),
    },
    ("gen2", 5): {"hlp": PaperFigures(93.0), "sto": PaperFigures(96.0)},
    ("gen2", 7): {"hlp": PaperFigures(93.0), "sto": PaperFigures(96.0)},
    ("gen2", 9): {"hlp": PaperFigures(95.0), "sto": PaperFigures(98.0)},
}
COMMON_NOTES = [
    (
        "Times are planning times per scene in seconds, means over all scenes of the condition (successes "
        "and failures): init = high-level plan + keypoint IK (plan_s + ik_s), optimisation = the low-level "
        "planner (the paper's: the stochastic trajectory optimiser), total = init + optimisation. The simulated "
        "execution (execute_s in results.csv) is excluded. Verification = the low-level planner's checks of a "
        "passing rollout before it accepts it (verify_s, part of optimisation); the ratio without it "
        "compares the search alone. The paper's figures are shown for its conditions only: the STO, open "
        "loop, true scene, no model error."
    ),
    (
        "Success % is followed by its 95 % Wilson interval; success = the world's verdict on the executed "
        "motion (world reference: finer physics than the planner's model; model: the planner's own): the "
        "target in the gripper's pre-grasp region at the end and no object fallen off the table. A false accept: the low-level planner accepted the motion in its model and the world failed it."
    ),
    (
        "A run that crashed (an exception in plan_and_execute) counts as a failure; its times are left out "
        "of the means."
    ),
]
NOTES = {
    "gen1": [
        (
            "The paper's init times are derived as total - optimisation (HLP 1.56 - 0.97 s, "
            "STO 17.88 - 17.84 s)."
        )
    ],
    "gen2": [
        (
            "Table III's times are not in our notes: the paper's time columns show n/a (null in "
            "summary.json) rather than invented numbers."
        )
    ],
}


PAPER_CELL = {"low_level": "sto", "execution": "open", "perception": "truth", "model_error": None}
"""What the paper ran: the STO, open loop, on the true scene, without model error."""


def paper_figures(generator: str, objects: int, cell: dict[str, object]) -> PaperFigures:
    """The paper's figures of a series (``cell``: its ``planner`` label, ``hlp`` or ``sto``, and its
    axes) in ``generator``'s condition of ``objects`` obstacles (all None where the paper has none,
    or the series is not run as the paper ran it, ``PAPER_CELL``)."""
    if any(cell.get(axis) != value for axis, value in PAPER_CELL.items()):
        return PaperFigures()
    table = PAPER.get((generator, None if generator == "gen1" else objects), {})
    return table.get(str(cell["planner"]), PaperFigures())


def notes(generators: tuple[str, ...]) -> list[str]:
    """The summary's notes for a study of ``generators``."""
    return [*COMMON_NOTES, *(note for g in generators for note in NOTES.get(g, []))]


__all__ = ["PAPER", "PAPER_CELL", "PaperFigures", "notes", "paper_figures"]
