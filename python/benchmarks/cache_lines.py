"""Cache lines a world's step fetches when many worlds step in one batch:
why steps per CPU-second fall as the batch grows
(docs/python-performance.md). Each world count's batch (the standard
configuration, one thread, random actions) runs under valgrind's
cachegrind, whose cache model has the processor's first-level data cache
and, as its last level, a cache of this machine's second-level size (read
from sysfs): a run of WARM + TIMED steps less one of WARM steps, per world
step, gives the instructions, the data reads and writes that miss the
first level, and those that also miss the second and go to the shared
third level or memory. Counts do not feel the machine's load.

    scripts/test-python   # the wheel in target/python-venv
    target/python-venv/bin/python python/benchmarks/cache_lines.py --out docs/python-cache-lines.json
    python3 python/benchmarks/cache_lines.py --render docs/python-cache-lines.json
"""

from __future__ import annotations

import argparse
import os
import platform
import re
import shutil
import subprocess
import sys
from pathlib import Path

import results_file  # beside this script

# World counts of the throughput benchmark's comparison, two between and
# two below, where the batch's lines stay in the second-level cache.
WORLDS = [16, 32, 64, 128, 256, 512, 1024]
# Steps before the counted ones (a world's first steps cost more: its
# robots plough through the spread pucks), and the counted steps.
WARM_STEPS = 50
TIMED_STEPS = 30

STEP_SCRIPT = """
import sys, numpy as np, zumo_swarm
worlds, steps = int(sys.argv[1]), int(sys.argv[2])
env = zumo_swarm.vector_env(worlds, threads=1)
env.reset(seed=1)
pool = np.random.default_rng(0).integers(0, 4, (64, worlds, 8))
for i in range(steps):
    env.step(pool[i % len(pool)])
"""


def second_level_cache() -> tuple[int, int, int]:
    """This machine's second-level cache: bytes, ways, line bytes (sysfs)."""
    base = Path("/sys/devices/system/cpu/cpu0/cache")
    for index in sorted(base.glob("index*")):
        if (index / "level").read_text().strip() == "2":
            size = (index / "size").read_text().strip()
            scale = {"K": 1024, "M": 1024 * 1024}.get(size[-1], 1)
            return (int(size.rstrip("KM")) * scale, int((index / "ways_of_associativity").read_text()),
                    int((index / "coherency_line_size").read_text()))
    sys.exit(f"cache_lines: {base} describes no second-level cache")


def counts(python: str, worlds: int, steps: int, cache: tuple[int, int, int]) -> dict[str, int]:
    """cachegrind's totals for `steps` batch steps of `worlds` worlds."""
    size, ways, line = cache
    cmd = ["valgrind", "--tool=cachegrind", "--cache-sim=yes", f"--LL={size},{ways},{line}",
           "--cachegrind-out-file=/dev/null", python, "-c", STEP_SCRIPT, str(worlds), str(steps)]
    # One BLAS thread: numpy's idle BLAS threads spin under valgrind, which
    # runs one thread at a time, and would count as the step's. A fixed
    # string hash: the two runs' interpreters then do the same work.
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "PYTHONHASHSEED": "0"}
    done = subprocess.run(cmd, capture_output=True, text=True, env=env)
    if done.returncode != 0:
        sys.exit(f"cache_lines: {' '.join(cmd[:5])} ... failed:\n{done.stderr[-2000:]}")
    totals = {}
    for key, label in [("instructions", r"I\s+refs"), ("first_level_misses", r"D1\s+misses"),
                       ("second_level_misses", r"LLd\s+misses")]:
        found = re.search(label + r":\s+([\d,]+)", done.stderr)
        if not found:
            sys.exit(f"cache_lines: cachegrind printed no {label!r} line:\n{done.stderr[-2000:]}")
        totals[key] = int(found.group(1).replace(",", ""))
    return totals


def measure(args: argparse.Namespace) -> dict:
    if shutil.which("valgrind") is None:
        sys.exit("cache_lines: valgrind is not installed")
    cache = second_level_cache()
    rows = []
    for worlds in args.worlds:
        short = counts(sys.executable, worlds, args.warm, cache)
        long = counts(sys.executable, worlds, args.warm + args.timed, cache)
        world_steps = worlds * args.timed
        rows.append({"worlds": worlds, **{k: (long[k] - short[k]) / world_steps for k in long}})
        print(f"{worlds} worlds: {rows[-1]}", file=sys.stderr, flush=True)
    return {
        "machine": platform.machine(),
        "cores": os.cpu_count(),
        "second_level_cache": dict(zip(["bytes", "ways", "line"], cache)),
        "warm_steps": args.warm,
        "timed_steps": args.timed,
        "rows": rows,
    }


def render(results: dict) -> str:
    """The markdown table of a results file."""
    cache = results["second_level_cache"]
    lines = [
        f"Counted by cachegrind on {results['machine']}, its last level modelled as this machine's second-level "
        f"cache ({cache['bytes'] // 1024:,} KiB, {cache['ways']} ways, {cache['line']}-byte lines); "
        f"steps {results['warm_steps']} to {results['warm_steps'] + results['timed_steps']} of every world, "
        "one thread. Per world step:",
        "",
        "| worlds | instructions | data misses, first level | data misses, second level | "
        "bytes fetched past the second level |",
        "|---:|---:|---:|---:|---:|",
    ]
    for row in results["rows"]:
        lines.append(f"| {row['worlds']:,} | {row['instructions']:,.0f} | {row['first_level_misses']:,.0f} "
                     f"| {row['second_level_misses']:,.0f} "
                     f"| {row['second_level_misses'] * cache['line']:,.0f} |")
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--render", metavar="RESULTS.json", help="print the markdown table of a results file")
    parser.add_argument("--worlds", type=int, nargs="+", default=WORLDS)
    parser.add_argument("--warm", type=int, default=WARM_STEPS)
    parser.add_argument("--timed", type=int, default=TIMED_STEPS)
    parser.add_argument("--out", help="results file to write (JSON)")
    parser.add_argument("--tiny", action="store_true", help="two and four worlds, a few steps: the method at a test's scale")
    args = parser.parse_args()
    if args.tiny:
        args.worlds, args.warm, args.timed = [2, 4], 2, 3
    if min(args.worlds) < 1 or args.warm < 0 or args.timed < 1:
        parser.error("--worlds must be at least 1, --warm at least 0 and --timed at least 1")
    results_file.render_or_measure(args, measure, render)


if __name__ == "__main__":
    main()
