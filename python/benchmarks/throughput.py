"""Throughput of the Python environments beside `host bench` and VMAS, in
one sitting: every configuration runs once per round, rounds alternate,
and the figures are medians over the rounds, stated as ratios to `host
bench` of the same sitting. Writes the raw runs as JSON; `--render` turns
such a file into the markdown table of docs/performance.md.

    cargo build --release -p host && scripts/test-python   # the release host, the wheel in target/python-venv
    python3 -m venv /tmp/vmas-venv && /tmp/vmas-venv/bin/pip install vmas
    target/python-venv/bin/python python/benchmarks/throughput.py --host target/release/host \\
        --vmas-python /tmp/vmas-venv/bin/python --rounds 2 --out docs/python-throughput.json
    python3 python/benchmarks/throughput.py --render docs/python-throughput.json
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import platform
import re
import resource
import statistics
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
HOST_STEPS = 300_000
VMAS = HERE / "vmas_steps.py"


# Every world of a vector_env row is timed over the same steps of its
# episode, WARM_STEPS to WARM_STEPS + TIMED_STEPS: early steps cost more
# (robots plough through the spread pucks), so a row that ran more steps
# per world would be measured on cheaper steps than one with more worlds.
WARM_STEPS = 300
TIMED_STEPS = 300
# A row repeats (fresh worlds, other seeds) until this many world-steps are
# timed, at most MAX_REPEATS times.
TIMED_WORLD_STEPS = 600_000
MAX_REPEATS = 64


def zumo_rate(worlds: int, threads: int, warm: int = WARM_STEPS) -> tuple[float, float]:
    """World steps per second and per CPU-second (all threads) of
    `vector_env(worlds)` in the standard configuration, random actions
    drawn before timing; each world timed over its steps `warm` to
    `warm + TIMED_STEPS`."""
    import numpy as np

    import zumo_swarm

    repeats = min(MAX_REPEATS, -(-TIMED_WORLD_STEPS // (worlds * TIMED_STEPS)))
    wall = cpu = 0.0
    for r in range(repeats):
        env = zumo_swarm.vector_env(worlds, threads=threads)
        env.reset(seed=1 + r)
        pool = np.random.default_rng(r).integers(0, 4, (64, worlds, 8))
        for i in range(warm):
            env.step(pool[i % len(pool)])
        start, cpu_start = time.perf_counter(), time.process_time()
        for i in range(TIMED_STEPS):
            env.step(pool[i % len(pool)])
        wall += time.perf_counter() - start
        cpu += time.process_time() - cpu_start
        env.close()
    steps = repeats * worlds * TIMED_STEPS
    return steps / wall, steps / cpu


def world_bytes(python: str) -> float:
    """Bytes of memory one world holds: the peak resident memory of a
    process that built and stepped 4,096 worlds, less that of one with 64,
    per extra world."""
    script = ("import resource, sys, numpy as np, zumo_swarm\n"
              "w = int(sys.argv[1]); env = zumo_swarm.vector_env(w, threads=1); env.reset(seed=1)\n"
              "for _ in range(5): env.step(np.zeros((w, 8), dtype=np.int64))\n"
              "print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss)")
    kib = [int(subprocess.run([python, "-c", script, str(w)], capture_output=True, text=True, check=True).stdout)
           for w in (64, 4096)]
    return (kib[1] - kib[0]) * 1024 / (4096 - 64)


def child_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def host_rate(host: str, args: list[str]) -> tuple[float, float]:
    """`host`'s own steps per second, and steps per CPU-second of the process."""
    before = child_cpu()
    out = subprocess.run([host, *args], capture_output=True, text=True, check=True).stdout
    cpu = child_cpu() - before
    rate = json.loads(out)["steps_per_second"] if "--json" in args else float(out.split()[0])
    return rate, HOST_STEPS / cpu


def vmas_rate(python: str, scenario: str, envs: int, calls: int) -> tuple[float, float]:
    cmd = [python, str(VMAS), "--scenario", scenario, "--envs", str(envs), "--steps", str(calls)]
    result = json.loads(subprocess.run(cmd, capture_output=True, text=True, check=True).stdout.splitlines()[-1])
    return result["steps_per_second"], result["steps_per_cpu_second"]


def configurations(host: str, vmas_python: str | None) -> list[dict]:
    threads = os.cpu_count() or 1
    bench = ["bench", "--steps", str(HOST_STEPS)]
    random = ["run", "--controller", "random", "--steps", str(HOST_STEPS), "--json"]
    rows = [
        {"name": "host bench (orbital construction, one thread)", "command": "host " + " ".join(bench),
         "run": lambda: host_rate(host, bench)},
        {"name": "host run, random actions (one thread)", "command": "host " + " ".join(random[:-1]),
         "run": lambda: host_rate(host, random)},
    ]
    for worlds, t in [(1, 1), (16, threads), (64, threads), (512, threads), (1024, threads), (4096, threads), (64, 1), (512, 1)]:
        rows.append({
            "name": f"vector_env, {worlds} world{'s' if worlds > 1 else ''}, {t} thread{'s' if t > 1 else ''}, random actions",
            "command": f"zumo_swarm.vector_env({worlds}, threads={t}).step(actions)",
            "run": lambda w=worlds, t=t: zumo_rate(w, t),
        })
    rows.append({
        "name": f"vector_env, 64 worlds, {threads} threads, random actions, each world's first {TIMED_STEPS} steps",
        "command": f"zumo_swarm.vector_env(64, threads={threads}).step(actions)",
        "run": lambda: zumo_rate(64, threads, warm=0),
    })
    if vmas_python:
        for scenario, envs, calls in [("pucks", 64, 5), ("transport", 64, 400), ("transport", 512, 100), ("transport", 4096, 20)]:
            what = "8 agents, 250 movable pucks" if scenario == "pucks" else "its transport scenario, 8 agents, 1 package"
            rows.append({
                "name": f"VMAS {what}, {envs} envs, CPU ({threads} torch threads)",
                "command": f"vmas_steps.py --scenario {scenario} --envs {envs} --steps {calls}",
                "run": lambda s=scenario, e=envs, c=calls: vmas_rate(vmas_python, s, e, c),
            })
    return rows


def measure(args) -> dict:
    rows = configurations(args.host, args.vmas_python)
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
        "date": datetime.date.today().isoformat(),
        "commit": commit,
        "machine": f"{platform.machine()}, {os.cpu_count()} cores",
        "rounds": args.rounds,
        "load_average": load,
        "bytes_per_world": world_bytes(sys.executable),
        "rows": [{k: v for k, v in row.items() if k != "run"} for row in rows],
    }


def render(results: dict) -> str:
    """The markdown table of a results file: medians, and ratios to `host
    bench` of the same sitting by wall clock, and per CPU-second (per core)
    to `host bench` and to `host run --controller random` (the workload of
    the random actions the environments are driven with)."""
    rows = results["rows"]
    base, base_cpu = statistics.median(rows[0]["runs"]), statistics.median(rows[0]["cpu_runs"])
    load = ", ".join(f"{x:.1f}" for x in results["load_average"])
    lines = [
        f"Measured at commit {results['commit']} on {results['machine']}, "
        f"{results['rounds']} alternating rounds (1-minute load average before and after each round: {load}). "
        "A step is one world's step (all 8 robots); medians over the rounds.",
        "",
        "| configuration | steps/s (each round) | median | vs host bench | steps per CPU-second | "
        "per core vs host bench | per core vs host run random |",
        "|---|---|---|---|---|---|---|",
    ]
    random_cpu = statistics.median(rows[1]["cpu_runs"])
    for row in rows:
        median, cpu = statistics.median(row["runs"]), statistics.median(row["cpu_runs"])
        runs = ", ".join(f"{r:,.0f}" for r in row["runs"])
        lines.append(
            f"| {row['name']} | {runs} | {median:,.0f} | {median / base:.3g} | {cpu:,.0f} | {cpu / base_cpu:.3g} "
            f"| {cpu / random_cpu:.3g} |"
        )
    lines.append("")
    world = results["bytes_per_world"]
    lines.append(
        f"A world holds about {world / 1024:,.0f} KB (peak resident memory of 4,096 worlds less that of 64, "
        f"per world): {512 * world / 2**20:,.0f} MB for 512 worlds, {4096 * world / 2**20:,.0f} MB for 4,096.")
    lines.append("")
    lines.extend(verdicts(rows, base_cpu, random_cpu))
    return "\n".join(lines) + "\n"


def verdicts(rows: list[dict], base_cpu: float, random_cpu: float) -> list[str]:
    """The targets: 64 worlds against native single-thread throughput, 512
    worlds against 64, and ours against VMAS' transport scenario at the same
    batch sizes; then the ratio to every VMAS run."""
    by_name = {row["name"]: row for row in rows}

    def ours(worlds: int) -> dict:
        """The row of `worlds` worlds on every core, timed past each world's first steps."""
        return next(row for name, row in by_name.items()
                    if re.fullmatch(f"vector_env, {worlds} worlds, [0-9]+ threads, random actions", name))

    def label(row: dict) -> str:
        return row["name"].split(", random")[0]

    def median(row: dict, key: str = "runs") -> float:
        return statistics.median(row[key])

    at64, at512 = ours(64), ours(512)
    cpu = median(at64, "cpu_runs")
    worst = min(cpu / base_cpu, cpu / random_cpu)
    scale = median(at512, "cpu_runs") / cpu
    out = [
        f"- Target (64 worlds: at least 50 % of native single-thread throughput per core): {label(at64)} "
        f"does {cpu / base_cpu:.2f}x `host bench`'s steps per CPU-second and {cpu / random_cpu:.2f}x those of `host run "
        f"--controller random` on the same workload: {'met' if worst >= 0.5 else 'NOT met'}.",
        f"- Target (512 worlds: at least 0.8 of the 64-world steps per CPU-second): {label(at512)} does "
        f"{scale:.2f}x {label(at64)}: {'met' if scale >= 0.8 else 'NOT met'}.",
    ]
    for worlds, need in [(64, 10), (512, 5)]:
        vmas = next((row for name, row in by_name.items()
                     if name.startswith("VMAS its transport") and f", {worlds} envs," in name), None)
        if vmas is None:
            continue
        wall_ratio = median(ours(worlds)) / median(vmas)
        cpu_ratio = median(ours(worlds), "cpu_runs") / median(vmas, "cpu_runs")
        out.append(
            f"- Target (at least {need}x VMAS' transport scenario at {worlds} worlds): {label(ours(worlds))} steps "
            f"{wall_ratio:,.1f}x as many worlds per second, {cpu_ratio:,.1f}x per CPU-second: "
            f"{'met' if min(wall_ratio, cpu_ratio) >= need else 'NOT met'}.")
    for row in rows:
        if row["name"].startswith("VMAS"):
            out.append(
                f"- {label(at64)} against {row['name']}: "
                f"{median(at64) / median(row):,.0f}x the steps per second, "
                f"{cpu / median(row, 'cpu_runs'):,.0f}x per CPU-second."
            )
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--render", metavar="RESULTS.json", help="print the markdown table of a results file")
    parser.add_argument("--host", default="target/release/host")
    parser.add_argument("--vmas-python", help="the Python of a virtual environment with vmas installed")
    parser.add_argument("--rounds", type=int, default=2)
    parser.add_argument("--out", help="results file to write (JSON)")
    args = parser.parse_args()
    if args.render:
        print(render(json.loads(Path(args.render).read_text())), end="")
        return
    results = measure(args)
    text = json.dumps(results, indent=1) + "\n"
    if args.out:
        tmp = Path(args.out + ".tmp")
        tmp.write_text(text)
        os.replace(tmp, args.out)
    print(render(results), end="")


if __name__ == "__main__":
    main()
