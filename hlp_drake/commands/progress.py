"""How ``run_scene`` shows a run as it happens: a line per stage, and bars for the rollouts and the simulation.

``ProgressListener`` has the methods of ``hlp_drake.systems.RunListener``: the stage lines go to
stdout as each stage ends; the optimiser's rollouts and the execution's simulated time are tqdm
bars on ``stream`` when it is a terminal (never in a file or a pipe, where their carriage returns
would run into the lines; off with ``quiet``). A plan on a perceived scene names each object by the
true object it was matched to, the perceived name beside.
"""

from __future__ import annotations

import sys
from collections.abc import Mapping
from typing import TextIO

from tqdm import tqdm

from hlp_drake.runtime.terminal import counted, is_terminal
from hlp_drake.systems.low_level.registry import LowLevelEntry, low_level_entry


def object_name(name: str, true_names: Mapping[str, str | None] | None = None) -> str:
    """``name``, or with ``true_names`` (perceived -> true) the true name and the perceived one beside:
    ``obstacle_9 (seen as object_2)``."""
    if true_names is None:
        return name
    true = true_names.get(name)
    if true is None:
        return f"{name} (seen; matches no true object)"
    return true if true == name else f"{true} (seen as {name})"


def plan_steps(plan, true_names: Mapping[str, str | None] | None = None) -> str:
    """A plan's keypoints as one line: ``start -> move Long RR -> release -> target`` (``true_names``:
    planned on a perceived scene, see ``object_name``)."""
    return (
        " -> ".join(
            k.action
            + (f" {k.element}" if k.action == "gap" else "")
            + (f" {object_name(k.element, true_names)}" if k.action == "move" else "")
            + (f" {k.direction}" if k.action == "move" else "")
            for k in plan.keypoints
        )
        or "(none)"
    )


class ProgressListener:
    """Prints each stage of a run as it happens (see the module's docstring)."""

    def __init__(self, *, quiet: bool = False, stream: TextIO = sys.stderr) -> None:
        self._bars = not quiet and is_terminal(stream)
        self._stream = stream
        self._true_names: Mapping[str, str | None] | None = None
        self._bar: tqdm | None = None
        self._shown = 0.0
        self._optimising = False  # the bar counts rollouts (not the closed loop's, during the execution)
        self._entry: LowLevelEntry | None = None  # the low-level planner running

    def _line(self, text: str) -> None:
        print(text, flush=True)

    def _open(self, **kwargs) -> None:
        if self._bars:
            self._bar = tqdm(file=self._stream, dynamic_ncols=True, leave=False, **kwargs)

    def close(self) -> None:
        """Take the open bar (if any) off the screen, e.g. when the run stops early."""
        if self._bar is not None:
            self._bar.close()
            self._bar = None

    def warning(self, message: str) -> None:
        """``warning: message`` on ``stream``, above the open bar (if any)."""
        line = f"warning: {message}"
        if self._bar is not None:
            self._bar.write(line, file=self._stream)
        else:
            print(line, file=self._stream, flush=True)

    def perceived(self, perception, seconds: float) -> None:
        if perception.ok:
            what = f"{counted(len(perception.objects), 'object')}, the target {perception.objects[0].name}"
        else:
            what = f"failed: {perception.reason}"
        self._line(
            f"perceive: {what} ({seconds:.2f} s: perception {perception.perception_s:.3f} s, the rest rendering)"
        )

    def named(self, names: Mapping[str, str | None]) -> None:
        self._true_names = names

    def planned(self, plan, seconds: float) -> None:
        what = f"plan: {plan_steps(plan, self._true_names)}" if plan.ok else f"plan: none ({plan.reason})"
        self._line(f"{what} ({seconds:.2f} s)")

    def solved(self, keyframes, trajectory, seconds: float) -> None:
        solved = sum(keyframes.success)
        failed = "" if keyframes.ok else f"; failed: {'; '.join(keyframes.failures)}"
        if keyframes.skipped:
            failed += f"; left out: {'; '.join(keyframes.skipped)}"
        if keyframes.candidate:
            failed += (
                f"; the plan's alternative {keyframes.candidate} runs in its place, the plan's IK "
                f"failed: {'; '.join(keyframes.replaced)}"
            )
        self._line(
            f"IK: {solved} of {len(keyframes.success)} keyframes, a {trajectory.end_time():.1f} s "
            f"trajectory ({seconds:.2f} s){failed}"
        )

    def optimising(self, low_level: str) -> None:
        self._entry = low_level_entry(low_level)
        self._open(desc=self._entry.step, unit=" rollouts")  # "optimise: 3 rollouts [00:01, 2.50 rollouts/s]"
        self._optimising = True

    def rollout(self, outcome) -> None:
        if self._bar is not None and self._optimising:
            self._bar.set_postfix_str(f"cost {outcome.cost:.3g}", refresh=False)
            self._bar.update()

    def optimised(self, result) -> None:
        self.close()
        self._optimising = False
        verdict = "success" if result.success else f"no success ({result.failure_reason})"
        entry = self._entry
        spent = f" after {counted(result.iterations, 'iteration')}, {counted(result.rollouts, 'rollout')}"
        spent = spent if entry is None or entry.rolls_out else ""
        self._line(f"{entry.step if entry else 'low-level'}: {verdict}{spent} ({result.optimise_s:.1f} s)")

    def executing(self, duration: float) -> None:
        self._line(f"execute: up to {duration:.1f} s simulated (reach, settle, grasp and lift)")
        self._shown = 0.0
        self._open(
            desc="execute",
            total=round(duration, 1),
            unit="s sim",
            bar_format=(
                "{desc}: {percentage:3.0f}%|{bar}| {n:.1f}/{total:.1f} s simulated [{elapsed}<{remaining}]"
            ),
        )

    def simulated(self, t: float) -> None:
        if self._bar is not None and t - self._shown >= 0.1:
            self._bar.update(round(t - self._shown, 1))
            self._shown += round(t - self._shown, 1)
        if self._bar is not None and t >= self._bar.total - 1e-9:
            self.close()

    def finished(self, result) -> None:
        self.close()
        self._line(f"execute: {result.simulated_s:.1f} s simulated in {result.timings['execute_s']:.1f} s")
