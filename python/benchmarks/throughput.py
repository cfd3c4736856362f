"""Throughput of the Python environments beside `host bench` and VMAS, in
one sitting: every configuration runs once per round, rounds alternate,
and the figures are medians over the rounds, stated as ratios to `host
bench` of the same sitting. Writes the raw runs as JSON; `--render` turns
such a file into the markdown table of docs/python.md and
docs/performance.md.

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
import resource
import statistics
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
HOST_STEPS = 300_000
VMAS = HERE / "vmas_steps.py"


def zumo_rate(worlds: int, threads: int, seconds: float = 2.0) -> tuple[float, float]:
    """World steps per second and per CPU-second (all threads) of
    `vector_env(worlds)` in the standard configuration, random actions
    drawn before timing."""
    import numpy as np

    import zumo_swarm

    env = zumo_swarm.vector_env(worlds, threads=threads)
    env.reset(seed=1)
    pool = np.random.default_rng(0).integers(0, 4, (64, worlds, 8))
    for a in pool[:8]:
        env.step(a)
    calls, start, cpu = 0, time.perf_counter(), time.process_time()
    while time.perf_counter() - start < seconds:
        for a in pool:
            env.step(a)
        calls += len(pool)
    wall, cpu = time.perf_counter() - start, time.process_time() - cpu
    return calls * worlds / wall, calls * worlds / cpu


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
    for worlds, t in [(1, 1), (16, threads), (64, threads), (64, 1)]:
        rows.append({
            "name": f"vector_env, {worlds} world{'s' if worlds > 1 else ''}, {t} thread{'s' if t > 1 else ''}, random actions",
            "command": f"zumo_swarm.vector_env({worlds}, threads={t}).step(actions)",
            "run": lambda w=worlds, t=t: zumo_rate(w, t),
        })
    if vmas_python:
        for scenario, envs, calls in [("pucks", 64, 3), ("pucks", 4096, 2), ("transport", 64, 10), ("transport", 4096, 4)]:
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
        f"Measured {results['date']} (commit {results['commit']}) on {results['machine']}, "
        f"{results['rounds']} alternating rounds in one sitting (1-minute load average before and after each round: {load}). "
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
    lines.extend(verdicts(rows, base_cpu, random_cpu))
    return "\n".join(lines) + "\n"


def verdicts(rows: list[dict], base_cpu: float, random_cpu: float) -> list[str]:
    """The issue's target at 64 worlds, and the ratios to every VMAS run."""
    by_name = {row["name"]: row for row in rows}
    ours = next(row for name, row in by_name.items() if name.startswith("vector_env, 64 worlds") and "threads" in name)
    wall, cpu = statistics.median(ours["runs"]), statistics.median(ours["cpu_runs"])
    worst = min(cpu / base_cpu, cpu / random_cpu)
    out = [
        f"- Target (64 worlds: at least 50 % of native single-thread throughput per core): {ours['name'].split(', random')[0]} "
        f"does {cpu / base_cpu:.2f}x `host bench`'s steps per CPU-second and {cpu / random_cpu:.2f}x those of `host run "
        f"--controller random` on the same workload: {'met' if worst >= 0.5 else 'NOT met'}."
    ]
    for row in rows:
        if row["name"].startswith("VMAS"):
            out.append(
                f"- {ours['name'].split(', random')[0]} against {row['name']}: "
                f"{wall / statistics.median(row['runs']):,.0f}x the steps per second, "
                f"{cpu / statistics.median(row['cpu_runs']):,.0f}x per CPU-second."
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
