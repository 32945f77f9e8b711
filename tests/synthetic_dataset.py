"""Writes a tiny dataset in the original public layout, for loader tests that need bad files."""

from __future__ import annotations

import tarfile
from pathlib import Path

import numpy as np

OBSTACLES = [
    ("FailOnTouchObstacleShort", 0.1275, -0.105, 0.05),
    ("FailOnTouchObstacleMed", 0.2575, -0.105, 0.10),
    ("FailOnTouchObstacleLong", -0.1925, -0.105, 0.15),
    ("FailOnTouchObstacleShort-1", 0.2175, 0.055, 0.05),
    ("FailOnTouchObstacleMed-1", -0.2325, 0.055, 0.10),
    ("FailOnTouchObstacleLong-1", -0.0125, 0.055, 0.15),
]
SCENE_LAYOUT = """object,x,y,z,width,height,depth
TableTop,0,0.73,-0.05,0.74,8.702278E-08,0.6000001
StartPoint,0,0.78,-0.25,0.05,0.04999995,0.05000001
EndPoint,0,0.78,-0.315,0.075,0.07500005,0.07499999
ShelfBoundary,0,0.87,-0.05,0.74,0.01999998,0.6
LeftBoundary,-0.36,0.795,-0.05,0.01999998,0.13,0.6
RightBoundary,0.36,0.795,-0.05,0.01999998,0.13,0.6
BackBoundary,0,0.795,0.24,0.74,0.13,0.02000001
"""
RESULTS_HEADER = "directory,experiment,ppid,session_num,trial_num,block_num,trial_num_in_block,start_time,end_time,type,trial_name,start_moved_time,target_reached_time,outcome\n"
FRAMES = 6


def hand_positions() -> np.ndarray:
    """Unity (x, y, z) of the hand: a straight reach from the start towards the target."""
    z = np.linspace(-0.25, 0.17, FRAMES)
    return np.column_stack([np.full(FRAMES, 0.01), np.full(FRAMES, 0.77), z])


def _movement(name: str, positions: np.ndarray, tracker: bool) -> str:
    prefix = "" if tracker else f"{name}_"
    header = ",".join(["time"] + [f"{prefix}{k}_{a}" for k in ("pos", "rot") for a in "xyz"])
    times = 100.0 + np.arange(len(positions)) / 90.0
    lines = [header] + [
        f"{t:.4f},{x:.4f},{y:.4f},{z:.4f},0.0,{10.0 * i:.1f},0.0"
        for i, (t, (x, y, z)) in enumerate(zip(times, positions))
    ]
    return "\n".join(lines) + "\n"


def write_trial(root: Path, subject: str, number: int) -> Path:
    folder = root / subject / f"T{number:03d}"
    (folder / "scene").mkdir(parents=True)
    (folder / "movement").mkdir()
    (folder / "scene" / f"scene_layout_T{number:03d}.csv").write_text(SCENE_LAYOUT)
    grid = ["object,x,y,z,width,height,depth", "Target,0,0.7727,0.175,0.05,0.0854,0.05"]
    grid += [f"{n},{x},0.79,{z},{w},0.12,0.05" for n, x, z, w in OBSTACLES]
    (folder / "scene" / f"grid_objects_layout_T{number:03d}.csv").write_text("\n".join(grid) + "\n")
    hand = hand_positions()
    for tracker, offset in (("Hand", 0.0), ("Wrist", -0.1), ("Elbow", -0.25), ("Shoulder", -0.4)):
        positions = hand + np.array([0.0, 0.0, offset])
        (folder / "movement" / f"{tracker}Tracker_movement_T{number:03d}.csv").write_text(
            _movement(f"{tracker}Tracker", positions, tracker=True)
        )
    for name, x, z, _ in [("Target", 0.0, 0.175, 0.05), *OBSTACLES]:
        positions = np.tile([x, 0.79, z], (FRAMES, 1))
        (folder / "movement" / f"{name}_movement_T{number:03d}.csv").write_text(
            _movement(name, positions, False)
        )
    (folder / "movement" / f"interaction_log_T{number:03d}.csv").write_text(
        "start_time,end_time,dominant_object,non_dominant_object,interaction_type\n"
        "100.0111,100.0333,Hand,FailOnTouchObstacleMed,LeftGate\n"
        "100.0444,,Hand,Target,PickedUp\n"
    )
    return folder


def write_dataset(root: Path, trials: dict[int, str] | None = None) -> Path:
    """A dataset/ folder with subject sub_01 (right-handed) and the given trial outcomes."""
    trials = trials or {5: "Success", 10: "Success", 11: "ArmInteraction"}
    root.mkdir(parents=True, exist_ok=True)
    (root / "participant_list.csv").write_text("ppid,handedness,gender,age\nsub_01,right,female,44\n")
    rows = [
        f"basic/ICRA01/S001,basic,ICRA01,1,{n},1,{n},100.0,100.0556,main,,100.0222,100.0444,{outcome}"
        for n, outcome in trials.items()
    ]
    (root / "sub_01").mkdir()
    (root / "sub_01" / "trial_results.csv").write_text(RESULTS_HEADER + "\n".join(rows) + "\n")
    for n in trials:
        write_trial(root, "sub_01", n)
    return root


def write_archive(folder: Path, archive: Path) -> Path:
    """Pack ``folder`` as ``hlp-vr-dataset/dataset/...`` into a .tar.xz, like the shared copy."""
    with tarfile.open(archive, "w:xz") as tar:
        tar.add(folder, arcname="hlp-vr-dataset/dataset")
    return archive
