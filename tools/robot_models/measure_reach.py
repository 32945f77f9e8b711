"""Measure how far the arms reach over a table with the gripper horizontal, to choose pedestal heights.

A development script, never imported by ``hlp_drake`` at run time::

    python tools/robot_models/measure_reach.py panda --mounts 0.5 0.6 0.7   # pedestal heights to compare
    python tools/robot_models/measure_reach.py iiwa14                      # the height in make_arms.py
    python tools/robot_models/measure_reach.py ur5                         # mobile_ur5, base joints at 0
    python tools/robot_models/measure_reach.py panda --home                # a ready configuration

For a table top at 0.70 and 0.80 m, the tcp is held 0.06 m above it (the keypoint IK's grasp height)
with its z (the approach) along world +x and its y horizontal, each within 0.2 rad, joint limits on,
at the points of a grid relative to the pedestal's axis: x from 0.1 to 1.2 m, y from -0.7 to 0.7 m,
5 cm apart. Drake's InverseKinematics (SNOPT) on a continuous plant that holds only the robot, its
pedestal welded to the world at the origin (for the mobile UR5: the base at the origin, its joints
held at 0, the grid relative to the riser's axis at x = 0.39 m), tries several seeds per point: the
solutions of the neighbouring points, a few hand-picked postures, then random configurations. Each
point gets the best of three grades its solutions reach:

1. *reachable*: a solution satisfies the constraints (the brief's measure);
2. *no self-collision*: one of them also keeps the arm, gripper and pedestal apart (Drake's
   collision filters apply);
3. *clear of the table too*: one of them also stays out of a table top whose front edge is 0.20 m
   in front of the pedestal's axis (the pedestal stands in front of the table; the arm must reach
   over the edge).

Reported per mount height and table height, for each grade:

* ``x_max`` / ``x_min``: the largest / smallest x reached on the centre line (y = 0);
* ``R``: the largest radius such that every grid point with x >= 0.25 m and at most R from the
  axis is reached (a half-disc in front of the pedestal; 0 if the point (0.25, 0) is not reached;
  the grid's |y| <= 0.7 m caps what can be seen of larger half-discs);
* ``R50``: the same for the points with x >= 0.50 m (for arms that cannot fold their wrist close to
  their own base with the gripper horizontal, such as the iiwa);
* ``n``: the number of grid points reached (of 667).

With several mounts it also says which mount makes the smaller R (and R50) over the two tables the
largest, per grade. Only the tcp's height above the mount matters (the column under the mount is
long enough in every case, and the table top is 0.06 m under the tcp), so the maps are computed once
per height difference on a model with a 1.5 m pedestal and shared between mount heights (0.70 m
table with a 0.60 m mount = 0.80 m table with a 0.70 m mount). The numbers move by about one grid
step (0.05 m) with the seeds' luck.

``--home`` looks for a ready configuration instead: the tcp 0.40 m (``--home-x``) in front of the
axis, horizontal along +x (within ``--home-tolerance`` rad), 0.06 m above a 0.75 m table, clear of
itself and of the table, as near as IK finds to the middle of the joint ranges.

The robot on its plant, its IK program and the collision grades are ``Arm`` in ``reach_arm.py``
beside this script; this script walks the grid, scores the maps and prints them.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))  # make_arms.py and reach_arm.py beside it

import make_arms
from reach_arm import TABLE_EDGE, Arm

TABLES = (0.70, 0.80)
CLEARANCE = 0.06  # tcp above the table top
XS = np.round(np.arange(0.10, 1.2001, 0.05), 3)
YS = np.round(np.arange(-0.70, 0.7001, 0.05), 3)
HALF_DISC_X = 0.25
SEEDS = 24  # attempts per point: neighbours' solutions, hand-picked postures, random ones
SEEDS_NEAR, NEAR = 64, 0.45  # more attempts within NEAR of the axis, where the wrist folds over the base
TALL = 1.5  # the mount of the model the maps are computed on

HOME_TARGET = (0.40, 0.0)  # tcp in front of the pedestal's axis for the ready configuration
HOME_TABLE = 0.75


Grades = dict[tuple[int, int], int]


def reach_map(arm: Arm, tcp_z: float) -> Grades:
    """Per grid index (i over XS, j over YS), with the tcp at height ``tcp_z``: 0 unreachable,
    1 reachable, 2 reachable free of self-collision, 3 also clear of the table.

    A first pass goes along the rows, outward from the centre line, each row from the pedestal
    outward, seeding each point with its neighbours' best solutions, the hand-picked postures and
    random configurations (``SEEDS`` attempts, ``SEEDS_NEAR`` near the pedestal; fewer once a grade-3
    solution is found). Repair passes then retry every point below grade 3 from the solutions of its
    eight neighbours, until nothing changes. Points farther than the arm's chain can stretch are
    skipped (unreachable).
    """
    best: dict[tuple[int, int], tuple[int, np.ndarray]] = {}
    centre = len(YS) // 2

    def point(i: int, j: int) -> np.ndarray:
        return np.array([arm.axis[0] + XS[i], arm.axis[1] + YS[j], tcp_z])

    def grade(key: tuple[int, int]) -> int:
        return best[key][0] if key in best else 0

    def attempt(key: tuple[int, int], seed: np.ndarray) -> bool:
        """Try ``seed``; True if the point's grade rose."""
        q = arm.solve(point(*key), seed)
        if q is None:
            return False
        g = 1 + arm.grade(q)
        if g > grade(key):
            best[key] = (g, q)
            return True
        return False

    order = sorted(range(len(YS)), key=lambda j: (abs(j - centre), j))
    for j in order:
        for i in range(len(XS)):
            key = (i, j)
            if not arm.may_reach(point(i, j)):
                continue
            neighbours = [(i - 1, j), (i, j - 1 if j > centre else j + 1), (i + 1, j)]
            seeds = [best[k][1] for k in sorted(neighbours, key=grade, reverse=True) if k in best]
            seeds += arm.nominal
            budget = SEEDS_NEAR if math.hypot(XS[i], YS[j]) <= NEAR else SEEDS
            for n in range(budget):
                if grade(key) == 3:
                    break
                attempt(key, seeds[n] if n < len(seeds) else arm.random_seed())
    tried: set[tuple[tuple[int, int], tuple[int, int], int]] = set()
    changed = True
    while changed:
        changed = False
        for j in order:
            for i in range(len(XS)):
                key = (i, j)
                if grade(key) == 3 or not arm.may_reach(point(i, j)):
                    continue
                for di in (-1, 0, 1):
                    for dj in (-1, 0, 1):
                        other = (i + di, j + dj)
                        if other == key or other not in best or (key, other, grade(other)) in tried:
                            continue
                        tried.add((key, other, grade(other)))
                        changed |= attempt(key, best[other][1])
    return {(i, j): grade((i, j)) for j in range(len(YS)) for i in range(len(XS))}


def half_disc(points: dict[tuple[int, int], bool], x0: float) -> float:
    """The largest radius R such that every grid point with x >= x0 and at most R from the
    pedestal's axis is reached (0 if the nearest such point is not)."""
    distances = {k: math.hypot(XS[k[0]], YS[k[1]]) for k in points if XS[k[0]] >= x0 - 1e-9}
    missing = [d for k, d in distances.items() if not points[k]]
    limit = min(missing) if missing else math.inf
    inside = [d for k, d in distances.items() if points[k] and d < limit - 1e-9]
    return max(inside) if inside else 0.0


def metrics(points: dict[tuple[int, int], bool]) -> dict[str, float | int | None]:
    centre = len(YS) // 2
    on_line = [XS[i] for (i, j), ok in points.items() if j == centre and ok]
    return {
        "x_max": max(on_line) if on_line else None,
        "R": half_disc(points, HALF_DISC_X),
        "R50": half_disc(points, 0.50),
        "x_min": min(on_line) if on_line else None,
        "n": sum(points.values()),
    }


LEVELS = ("reachable", "no self-collision", "clear of the table too")


def print_map(points: Grades, title: str) -> None:
    print(f"  {title}: rows y +0.70 .. -0.70, columns x 0.10 .. 1.20; . unreachable, 1/2/3 = {LEVELS}")
    for j in reversed(range(len(YS))):
        row = "".join(".123"[points[(i, j)]] for i in range(len(XS)))
        print(f"  {YS[j]:+5.2f} {row}")


def fmt(value) -> str:
    return "-" if value is None else f"{value:.2f}" if isinstance(value, float) else str(value)


def arm_for(name: str, above_mount: float) -> tuple[Arm, float]:
    """A model for maps with the tcp ``above_mount`` over the arm's mount, and the tcp's height."""
    if name == "ur5":
        from make_mobile_ur5 import MOUNT_HEIGHT as mount
    else:
        mount = TALL
    arm = Arm(name, mount, table_top=mount + above_mount - CLEARANCE)
    return arm, mount + above_mount


def measure(name: str, mounts: list[float], show_maps: bool) -> dict:
    """Print and return the metrics per (mount, table) and grade level."""
    cache: dict[float, Grades] = {}
    results = {}
    print(f"{name}: tcp horizontal along +x, {CLEARANCE} m above the table top; the table's edge")
    print(
        f"{TABLE_EDGE} m in front of the pedestal's axis; x_max, R, x_min in m, n of {len(XS) * len(YS)} points"
    )
    print("mount table | " + " | ".join(f"{level[:26]:26}" for level in LEVELS) + " | s")
    print("            | " + " | ".join("x_max R    R50  x_min n   " for _ in LEVELS) + " |")
    for mount in mounts:
        for table in TABLES:
            above_mount = round(table + CLEARANCE - mount, 4)
            start = time.perf_counter()
            if above_mount not in cache:
                arm, tcp_z = arm_for(name, above_mount)
                cache[above_mount] = reach_map(arm, tcp_z)
            points = cache[above_mount]
            row = [metrics({k: g >= level for k, g in points.items()}) for level in (1, 2, 3)]
            results[(mount, table)] = row
            cells = " | ".join(
                f"{fmt(m['x_max']):5} {fmt(m['R']):4} {fmt(m['R50']):4} {fmt(m['x_min']):5} {m['n']:3d} "
                for m in row
            )
            print(f"{mount:5.2f} {table:4.2f}  | {cells} | {time.perf_counter() - start:.0f}", flush=True)
            if show_maps:
                print_map(points, f"{name}, mount {mount:.2f} m, table {table:.2f} m")
    if len(mounts) > 1:
        for key in ("R", "R50"):
            for level, title in enumerate(LEVELS):
                worst = {m: min(results[(m, t)][level][key] for t in TABLES) for m in mounts}
                top = max(worst.values())
                best = ", ".join(f"{m:.2f}" for m in mounts if worst[m] == top)
                print(
                    f"{key}, {title}: the smaller over the tables is largest ({top:.2f} m) at mounts {best}"
                )
    return results


def home(
    name: str, mount: float, x: float = HOME_TARGET[0], tolerance: float = 1e-3, tries: int = 40
) -> np.ndarray | None:
    """A ready configuration: tcp horizontal along +x (within ``tolerance`` rad; fingers opening along
    world y), CLEARANCE above a HOME_TABLE table, ``x`` in front of the pedestal's axis, clear of
    itself and of the table, as near as IK finds to the middle of the joint ranges (a quadratic cost;
    seeds: the hand-picked postures, then random ones)."""
    arm = Arm(name, mount, table_top=HOME_TABLE, angle_tolerance=tolerance)
    p = np.array([arm.axis[0] + x, arm.axis[1] + HOME_TARGET[1], HOME_TABLE + CLEARANCE])
    lower, upper = arm.lower[arm.arm_index], arm.upper[arm.arm_index]
    middle = np.clip((lower + upper) / 2.0, -math.pi, math.pi)
    arm.ik.prog().AddQuadraticErrorCost(np.eye(len(middle)), middle, arm.ik.q()[arm.arm_index])
    best = None
    for k in range(tries):
        seed = arm.nominal[k] if k < len(arm.nominal) else arm.random_seed()
        q = arm.solve(p, seed)
        if q is None or arm.grade(q) < 2:
            continue
        distance = float(np.linalg.norm(q - middle))
        if best is None or distance < best[0] - 1e-6:
            best = (distance, q)
    if best is None:
        print(f"{name}: no ready configuration found with the tcp {x} m in front")
        return None
    q = best[1]
    arm.plant.SetPositions(arm.plant_context, arm.full(q))
    X = arm.tcp.CalcPoseInWorld(arm.plant_context)
    print(f"{name} home (mount {arm.mount:.2f} m): q = ({', '.join(f'{v:.4f}' for v in q)})")
    print(f"  {best[0]:.2f} rad from the middle of the joint ranges; tcp at {np.round(X.translation(), 4)},")
    print(f"  its axes in the world (columns x y z):\n{np.round(X.rotation().matrix(), 3)}")
    return q


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("arm", choices=("panda", "iiwa14", "ur5"))
    parser.add_argument(
        "--mounts", type=float, nargs="+", help="pedestal heights, m (default: make_arms.py's)"
    )
    parser.add_argument("--maps", action="store_true", help="print the reach maps")
    parser.add_argument("--home", action="store_true", help="find a ready configuration instead")
    parser.add_argument(
        "--home-x", type=float, default=HOME_TARGET[0], help="tcp x of the ready configuration"
    )
    parser.add_argument("--home-tolerance", type=float, default=1e-3, help="its tcp's tilt, rad")
    args = parser.parse_args(argv)
    default = {"panda": make_arms.PANDA_MOUNT, "iiwa14": make_arms.IIWA_MOUNT, "ur5": 0.80}[args.arm]
    if args.home:
        home(args.arm, default, args.home_x, args.home_tolerance)
        return 0
    mounts = [default] if args.arm == "ur5" or not args.mounts else args.mounts
    measure(args.arm, mounts, args.maps)
    return 0


if __name__ == "__main__":
    sys.exit(main())
