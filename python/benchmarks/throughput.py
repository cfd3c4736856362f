"""Throughput of the Python environments beside `host bench` and VMAS, in
one sitting: every configuration runs once per round, rounds alternate,
and the figures are medians over the rounds, stated as ratios to `host
bench` of the same sitting. Ours and VMAS run at the same world counts,
each at one thread and then on every core; VMAS is the version pinned
here (VMAS_VERSION), its `transport` scenario with its defaults and our
standard configuration's bodies (`pucks`, python/benchmarks/vmas_steps.py).
Writes the raw runs as JSON, the load average and VMAS's and PyTorch's
versions with them; `--render` turns such a file into the markdown table
of docs/python-performance.md, `--render-vmas` into docs/python.md's comparison.
`--tiny` runs every step of the method at a scale a test can afford.

    cargo build --release -p host && scripts/test-python   # the release host, the wheel in target/python-venv
    python3 -m venv /tmp/vmas-venv && /tmp/vmas-venv/bin/pip install vmas==1.5.2
    target/python-venv/bin/python python/benchmarks/throughput.py --host target/release/host \\
        --vmas-python /tmp/vmas-venv/bin/python --rounds 3 --out docs/python-throughput.json
    python3 python/benchmarks/throughput.py --render docs/python-throughput.json
    python3 python/benchmarks/throughput.py --render-vmas docs/python-throughput.json
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import resource
import statistics
import subprocess
import sys
import time
from pathlib import Path

import results_file  # beside this script

HERE = Path(__file__).resolve().parent
VMAS = HERE / "vmas_steps.py"
# The VMAS release compared with: `measure` refuses another.
VMAS_VERSION = "1.5.2"


class Scale:
    """How much each configuration runs: the published one, or `--tiny`'s,
    which runs every step of the method (both sides, every thread count,
    the rendering) in seconds, for the test suite."""

    def __init__(self, tiny: bool):
        # `host bench` and `host run` steps
        self.host_steps = 2_000 if tiny else 300_000
        # World counts compared at one thread and on every core.
        self.worlds = [4, 16, 32] if tiny else [64, 512, 1024]
        # Beside those, on every core only.
        self.more_worlds = [1, 2, 64] if tiny else [1, 16, 4096]
        # Every world of a vector_env row is timed over the same steps of
        # its episode, warm to warm + timed: early steps cost more (robots
        # plough through the spread pucks), so a row that ran more steps
        # per world would be measured on cheaper steps than one with more
        # worlds.
        self.warm_steps = 10 if tiny else 300
        self.timed_steps = 10 if tiny else 300
        # A row repeats (fresh worlds, other seeds) until this many
        # world-steps are timed, at most MAX_REPEATS times.
        self.timed_world_steps = 1_000 if tiny else 600_000
        # The worlds whose peak memory difference gives a world's bytes.
        self.memory_worlds = (4, 64) if tiny else (64, 4096)


MAX_REPEATS = 64


def zumo_rate(scale: Scale, worlds: int, threads: int, warm: int) -> tuple[float, float]:
    """World steps per second and per CPU-second (all threads) of
    `vector_env(worlds)` in the standard configuration, random actions
    drawn before timing; each world timed over its steps `warm` to
    `warm + scale.timed_steps`."""
    import numpy as np

    import zumo_swarm

    repeats = min(MAX_REPEATS, -(-scale.timed_world_steps // (worlds * scale.timed_steps)))
    wall = cpu = 0.0
    for r in range(repeats):
        env = zumo_swarm.vector_env(worlds, threads=threads)
        env.reset(seed=1 + r)
        pool = np.random.default_rng(r).integers(0, 4, (64, worlds, 8))
        for i in range(warm):
            env.step(pool[i % len(pool)])
        start, cpu_start = time.perf_counter(), time.process_time()
        for i in range(scale.timed_steps):
            env.step(pool[i % len(pool)])
        wall += time.perf_counter() - start
        cpu += time.process_time() - cpu_start
        env.close()
    steps = repeats * worlds * scale.timed_steps
    return steps / wall, steps / cpu


# The puck count of the second memory measurement: a world's bytes less
# those of one with this many pucks are its pucks' share.
FEW_PUCKS = 5
# The standard configuration's pucks, which every vector_env row steps.
STANDARD_PUCKS = 250


def world_bytes(python: str, scale: Scale, pucks: int | None = None) -> float:
    """Bytes of memory one world holds (of `pucks` pucks, else the
    standard configuration's): the peak resident memory of a process that
    built and stepped many worlds, less that of one with few, per extra
    world. The peak is the process's own (`VmHWM`, which a new program
    starts afresh; `ru_maxrss` would keep this process's, which the child
    was forked from)."""
    script = ("import re, sys, numpy as np, zumo_swarm\n"
              "w = int(sys.argv[1]); p = {} if sys.argv[2] == 'standard' else {'pucks': int(sys.argv[2])}\n"
              "env = zumo_swarm.vector_env(w, threads=1, **p); env.reset(seed=1)\n"
              "for _ in range(5): env.step(np.zeros((w, 8), dtype=np.int64))\n"
              "print(re.search(r'VmHWM:\\s*(\\d+) kB', open('/proc/self/status').read()).group(1))")
    few, many = scale.memory_worlds
    kib = [int(subprocess.run([python, "-c", script, str(w), str(pucks or "standard")], capture_output=True,
                              text=True, check=True).stdout)
           for w in (few, many)]
    return (kib[1] - kib[0]) * 1024 / (many - few)


def child_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def host_rate(host: str, args: list[str], steps: int) -> tuple[float, float]:
    """`host`'s own steps per second, and steps per CPU-second of the process."""
    before = child_cpu()
    out = subprocess.run([host, *args], capture_output=True, text=True, check=True).stdout
    cpu = child_cpu() - before
    rate = json.loads(out)["steps_per_second"] if "--json" in args else float(out.split()[0])
    return rate, steps / cpu


def vmas_rate(python: str, args: list[str]) -> tuple[float, float]:
    """vmas_steps.py's steps per second and per CPU-second for `args`."""
    cmd = [python, str(VMAS), *args]
    result = json.loads(subprocess.run(cmd, capture_output=True, text=True, check=True).stdout.splitlines()[-1])
    return result["steps_per_second"], result["steps_per_cpu_second"]


def vmas_versions(python: str) -> dict:
    """VMAS's and PyTorch's versions in `python`; refuses a VMAS other than
    VMAS_VERSION, the one the published figures were measured with."""
    cmd = [python, "-c", "import json, torch, vmas; print(json.dumps({'vmas': vmas.__version__, 'torch': torch.__version__}))"]
    versions = json.loads(subprocess.run(cmd, capture_output=True, text=True, check=True).stdout)
    if versions["vmas"] != VMAS_VERSION:
        sys.exit(f"throughput: {python} has VMAS {versions['vmas']}, the comparison is pinned to {VMAS_VERSION} "
                 f"(pip install vmas=={VMAS_VERSION})")
    return versions


def zumo_name(worlds: int, threads: int) -> str:
    return f"vector_env, {worlds} world{'s' if worlds > 1 else ''}, {threads} thread{'s' if threads > 1 else ''}, random actions"


def vmas_name(scenario: str, envs: int, threads: int) -> str:
    what = "8 agents, 250 movable pucks" if scenario == "pucks" else "its transport scenario, its defaults (4 agents, 1 package)"
    return f"VMAS {what}, {envs} envs, CPU ({threads} torch thread{'s' if threads > 1 else ''})"


def configurations(host: str, vmas_python: str | None, scale: Scale) -> list[dict]:
    """Every row of one round, each with what it is (`side`, `worlds`,
    `threads`, `scenario`) for the comparisons, and how to run it."""
    cores = os.cpu_count() or 1
    steps = scale.host_steps
    bench = ["bench", "--steps", str(steps)]
    random = ["run", "--controller", "random", "--steps", str(steps), "--json"]
    rows = [
        {"name": "host bench (orbital construction, one thread)", "command": "host " + " ".join(bench),
         "side": "host", "run": lambda: host_rate(host, bench, steps)},
        {"name": "host run, random actions (one thread)", "command": "host " + " ".join(random[:-1]),
         "side": "host", "run": lambda: host_rate(host, random, steps)},
    ]
    shapes = [(w, 1) for w in scale.worlds] + [(w, cores) for w in sorted(set(scale.worlds + scale.more_worlds))]
    for worlds, threads in shapes:
        rows.append({
            "name": zumo_name(worlds, threads), "command": f"zumo_swarm.vector_env({worlds}, threads={threads}).step(actions)",
            "side": "ours", "worlds": worlds, "threads": threads,
            "run": lambda w=worlds, t=threads: zumo_rate(scale, w, t, scale.warm_steps),
        })
    rows.append({
        "name": f"{zumo_name(scale.worlds[0], cores)}, each world's first {scale.timed_steps} steps",
        "command": f"zumo_swarm.vector_env({scale.worlds[0]}, threads={cores}).step(actions)",
        "side": "ours-first-steps", "worlds": scale.worlds[0], "threads": cores,
        "run": lambda: zumo_rate(scale, scale.worlds[0], cores, 0),
    })
    if vmas_python:
        for threads in sorted({1, cores}):
            # transport: about as many world steps as ours per row; pucks:
            # VMAS's step over 258 bodies is slow, so few calls
            cases = [("transport", envs, max(20, 25_600 // envs), 10) for envs in scale.worlds]
            cases += [("pucks", envs, 3, 2) for envs in scale.worlds[:2]]
            for scenario, envs, calls, warmup in cases:
                args = ["--scenario", scenario, "--envs", str(envs), "--steps", str(calls),
                        "--warmup", str(warmup), "--threads", str(threads)]
                rows.append({
                    "name": vmas_name(scenario, envs, threads), "command": "vmas_steps.py " + " ".join(args),
                    "side": "vmas", "scenario": scenario, "worlds": envs, "threads": threads,
                    "run": lambda a=args: vmas_rate(vmas_python, a),
                })
    return rows


def processor() -> str:
    """The processor and its caches as `lscpu` names them: the caches are
    what decides how the steps per second hold as the worlds grow."""
    try:
        out = subprocess.run(["lscpu"], capture_output=True, text=True, check=True).stdout
    except (OSError, subprocess.CalledProcessError):
        return platform.processor() or "unknown processor"
    fields = dict(line.split(":", 1) for line in out.splitlines() if ":" in line)
    get = lambda key: " ".join(fields.get(key, "?").split())
    return f"{get('Model name')}, L2 {get('L2 cache')}, L3 {get('L3 cache')}"


def measure(args) -> dict:
    scale = Scale(args.tiny)
    versions = vmas_versions(args.vmas_python) if args.vmas_python else None
    rows = configurations(args.host, args.vmas_python, scale)
    for row in rows:
        row["runs"], row["cpu_runs"] = [], []
    load = [os.getloadavg()[0]]
    for round_ in range(args.rounds):
        for row in rows:
            wall, cpu = row["run"]()
            row["runs"].append(wall)
            row["cpu_runs"].append(cpu)
            print(f"round {round_ + 1}: {row['name']}: {wall:,.0f} steps/s, {cpu:,.0f} per CPU-s", file=sys.stderr, flush=True)
        load.append(os.getloadavg()[0])
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    return {
        "commit": commit,
        "machine": f"{platform.machine()}, {os.cpu_count()} cores",
        "processor": processor(),
        "rounds": args.rounds,
        "load_average": load,
        "versions": versions,
        "bytes_per_world": world_bytes(sys.executable, scale),
        "bytes_per_world_few_pucks": [FEW_PUCKS, world_bytes(sys.executable, scale, FEW_PUCKS)],
        "memory_worlds": list(scale.memory_worlds),
        "rows": [{k: v for k, v in row.items() if k != "run"} for row in rows],
    }


def median(row: dict, key: str = "runs") -> float:
    return statistics.median(row[key])


def load_line(results: dict) -> str:
    load = ", ".join(f"{x:.1f}" for x in results["load_average"])
    versions = results.get("versions")
    vmas = f"; VMAS {versions['vmas']}, PyTorch {versions['torch']} on CPU" if versions else ""
    return (f"Measured at commit {results['commit']} on {results['machine']} ({results['processor']}), "
            f"{results['rounds']} alternating rounds "
            f"(1-minute load average before and after each round: {load}){vmas}. "
            "A step is one world's step (all its robots); medians over the rounds.")


def render(results: dict) -> str:
    """The markdown table of a results file: medians, and ratios to `host
    bench` of the same sitting by wall clock, and per CPU-second (per core)
    to `host bench` and to `host run --controller random` (the workload of
    the random actions the environments are driven with)."""
    rows = results["rows"]
    base, base_cpu = median(rows[0]), median(rows[0], "cpu_runs")
    lines = [
        load_line(results),
        "",
        "| configuration | steps/s (each round) | median | vs host bench | steps per CPU-second | "
        "per core vs host bench | per core vs host run random |",
        "|---|---|---|---|---|---|---|",
    ]
    random_cpu = median(rows[1], "cpu_runs")
    for row in rows:
        wall, cpu = median(row), median(row, "cpu_runs")
        runs = ", ".join(f"{r:,.0f}" for r in row["runs"])
        lines.append(
            f"| {row['name']} | {runs} | {wall:,.0f} | {wall / base:.3g} | {cpu:,.0f} | {cpu / base_cpu:.3g} "
            f"| {cpu / random_cpu:.3g} |"
        )
    lines.append("")
    world = results["bytes_per_world"]
    few, many = results["memory_worlds"]
    lines.append(
        f"A world holds about {world / 1024:,.0f} KB (peak resident memory of {many:,} worlds less that of {few:,}, "
        f"per world): {512 * world / 2**20:,.0f} MB for 512 worlds, {4096 * world / 2**20:,.0f} MB for 4,096.")
    if "bytes_per_world_few_pucks" in results:
        pucks, small = results["bytes_per_world_few_pucks"]
        per_puck = (world - small) / (STANDARD_PUCKS - pucks)
        lines[-1] += (f" With {pucks} pucks instead of {STANDARD_PUCKS} a world holds about {small / 1024:,.0f} KB: "
                      f"about {per_puck:,.0f} bytes a puck, the rest the world's own.")
    lines.append("")
    lines.extend(verdicts(rows))
    return "\n".join(lines) + "\n"


def find(rows: list[dict], side: str, worlds: int, threads: int, scenario: str | None = None) -> dict | None:
    return next((row for row in rows if row["side"] == side and row.get("worlds") == worlds
                 and row.get("threads") == threads and row.get("scenario") == scenario), None)


def verdicts(rows: list[dict]) -> list[str]:
    """The targets: 64 worlds against native single-thread throughput, and
    how the steps per CPU-second hold as the batch grows (512 worlds at
    least 0.8 of 64, 1,024 at least 0.7), at one thread and on every core."""
    base_cpu, random_cpu = median(rows[0], "cpu_runs"), median(rows[1], "cpu_runs")
    ours = [row for row in rows if row["side"] == "ours"]
    cores = max(row["threads"] for row in ours)
    small = min(row["worlds"] for row in ours if row["threads"] == 1)
    at_small = find(rows, "ours", small, cores)
    cpu = median(at_small, "cpu_runs")
    worst = min(cpu / base_cpu, cpu / random_cpu)
    out = [
        f"- Target ({small} worlds: at least 50 % of native single-thread throughput per core): {at_small['name']} "
        f"does {cpu / base_cpu:.2f}x `host bench`'s steps per CPU-second and {cpu / random_cpu:.2f}x those of `host run "
        f"--controller random` on the same workload: {'met' if worst >= 0.5 else 'NOT met'}.",
    ]
    larger = sorted({row["worlds"] for row in ours if row["threads"] == 1} - {small})
    for worlds, need in zip(larger, (0.8, 0.7)):
        for threads in sorted({1, cores}):
            ratio = median(find(rows, "ours", worlds, threads), "cpu_runs") / median(find(rows, "ours", small, threads), "cpu_runs")
            out.append(
                f"- Target ({worlds:,} worlds at least {need} of {small} worlds' steps per CPU-second), "
                f"{threads} thread{'s' if threads > 1 else ''}: {ratio:.2f}x: {'met' if ratio >= need else 'NOT met'}.")
    return out


def render_vmas(results: dict) -> str:
    """docs/python.md's comparison: ours beside VMAS at the same world
    counts, both at one thread and both on every core, steps per second and
    per CPU-second, and the targets against VMAS's `transport` at one
    thread (at least 10x at the smallest count, 3x at the next)."""
    rows = results["rows"]
    lines = [
        load_line(results),
        "",
        "| worlds | threads | ours: steps/s | per CPU-s | VMAS transport (defaults): steps/s | per CPU-s "
        "| ours / transport (steps/s, per CPU-s) | VMAS 8 agents + 250 pucks: steps/s | ours / pucks (steps/s) |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    ours = sorted({(row["worlds"], row["threads"]) for row in rows if row["side"] == "ours"},
                  key=lambda wt: (wt[1], wt[0]))
    targets = []
    for worlds, threads in ours:
        transport = find(rows, "vmas", worlds, threads, "transport")
        if transport is None:
            continue
        mine = find(rows, "ours", worlds, threads)
        pucks = find(rows, "vmas", worlds, threads, "pucks")
        wall_ratio, cpu_ratio = median(mine) / median(transport), median(mine, "cpu_runs") / median(transport, "cpu_runs")
        puck_cells = (f"{median(pucks):,.0f} | {median(mine) / median(pucks):,.0f}x" if pucks else "not run | not run")
        lines.append(
            f"| {worlds:,} | {threads} | {median(mine):,.0f} | {median(mine, 'cpu_runs'):,.0f} | {median(transport):,.0f} "
            f"| {median(transport, 'cpu_runs'):,.0f} | {wall_ratio:,.1f}x, {cpu_ratio:,.1f}x | {puck_cells} |")
        if threads == 1:
            targets.append((worlds, min(wall_ratio, cpu_ratio)))
    lines.append("")
    for (worlds, ratio), need in zip(targets, (10, 3)):
        lines.append(f"- Target (at least {need}x VMAS' transport at {worlds:,} worlds, one thread each): "
                     f"{ratio:,.1f}x: {'met' if ratio >= need else 'NOT met'}.")
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--render", metavar="RESULTS.json", help="print the markdown table of a results file")
    parser.add_argument("--render-vmas", metavar="RESULTS.json", help="print the comparison with VMAS of a results file")
    parser.add_argument("--host", default="target/release/host")
    parser.add_argument("--vmas-python", help="the Python of a virtual environment with VMAS_VERSION installed")
    parser.add_argument("--rounds", type=int, default=2)
    parser.add_argument("--tiny", action="store_true", help="every step of the method at a test's scale")
    parser.add_argument("--out", help="results file to write (JSON)")
    args = parser.parse_args()
    if args.render_vmas:
        print(render_vmas(json.loads(Path(args.render_vmas).read_text())), end="")
        return
    results_file.render_or_measure(args, measure, render)


if __name__ == "__main__":
    main()
