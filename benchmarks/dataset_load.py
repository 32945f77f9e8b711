"""Cold and warm full-load times of the VR dataset's structured trials.

    python benchmarks/dataset_load.py [--dataset PATH] [--repeats 3]

Cold: a fresh, empty cache directory (parses every CSV). Warm: the cache written by the cold run.
"Full load" materialises every structured trial (Scene, tracks, interaction log).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import tempfile
import time
from pathlib import Path

from hlp_drake.dataset import STRUCTURED, Dataset

DEFAULT = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "hlp-vr-dataset.tar.xz"


def full_load(path: str, cache: Path) -> tuple[float, float, str]:
    start = time.perf_counter()
    dataset = Dataset(path, cache_dir=cache, progress=False)
    opened = time.perf_counter()
    frames = sum(len(t.trackers["hand"]) for t in dataset.trials(dataset.select(category=STRUCTURED)))
    assert frames > 0
    return opened - start, time.perf_counter() - start, dataset.cache_status


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--dataset", default=os.environ.get("HLP_DATASET", str(DEFAULT)))
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        cold_open, cold_total, status = full_load(args.dataset, Path(tmp))
        assert status == "built"
        warm = [full_load(args.dataset, Path(tmp)) for _ in range(args.repeats)]
    result = {
        "machine": f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}",
        "dataset": args.dataset,
        "cold_full_load_s": round(cold_total, 2),
        "cold_cache_build_s": round(cold_open, 2),
        "warm_open_s_median": round(statistics.median(w[0] for w in warm), 3),
        "warm_full_load_s_median": round(statistics.median(w[1] for w in warm), 3),
        "cold_to_warm_ratio": round(cold_total / statistics.median(w[1] for w in warm), 1),
    }
    print(json.dumps(result, indent=2))


if __name__ == "__main__":
    main()
