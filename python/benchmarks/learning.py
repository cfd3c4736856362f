"""Learning figures of the examples and the rewards (docs/python-results.md,
"Examples that learn"): each learner trains for the same budget of
world-steps on the standard annulus (8 robots, 250 pucks, disc sensors),
its policy is exported as a policy blob, and the blob's greedy table is
run on 10 evaluation seeds; random actions and robots standing still
(forward speed 0) are run on the same seeds. Writes the runs as JSON;
`--render` turns such a file into the table of docs/python-results.md.

    scripts/test-python                                    # the wheel in target/python-venv
    python3 -m venv /tmp/ml && /tmp/ml/bin/pip install stable-baselines3 target/wheels/zumo_swarm-*.whl
    /tmp/ml/bin/python python/benchmarks/learning.py --host target/release/host --out docs/python-learning.json
    python3 python/benchmarks/learning.py --render docs/python-learning.json
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import results_file  # beside this script

HERE = Path(__file__).resolve().parent


def host_formations(host: str, policy: Path, steps: int, seed: int) -> int:
    """Formations of ``host run`` with the exported blob, as a robot would run it."""
    out = subprocess.run(
        [host, "run", "--controller", f"policy:{policy}", "--steps", str(steps), "--seed", str(seed), "--json"],
        capture_output=True, text=True, check=True,
    )
    return json.loads(out.stdout)["formations"]


def timed(f):
    start, cpu = time.perf_counter(), time.process_time()
    result = f()
    return result, {"seconds": round(time.perf_counter() - start, 1), "cpu_seconds": round(time.process_time() - cpu, 1)}


def run(args) -> dict:
    import numpy as np

    import zumo_swarm

    sys.path.insert(0, str(HERE.parent / "examples"))
    from run_log import EVAL_SEEDS, evaluate  # the examples' held-out evaluation

    rng = np.random.default_rng(0)
    random_act = lambda obs: rng.integers(0, 4, obs.shape)
    rows = []
    load = [os.getloadavg()[0]]
    e = args.eval_steps

    def baseline(name, **settings):
        result, cost = timed(lambda: evaluate(random_act, e, **settings))
        rows.append({"learner": name, "reward": None, "steps": 0, "trained_formations": None, "exported_formations": None, **result, **cost})
        print(rows[-1], flush=True)

    def learned(name, reward, train_and_table, extra=None):
        (table, trained, env), cost = timed(train_and_table)
        with tempfile.TemporaryDirectory() as d:
            path = zumo_swarm.export_policy(Path(d) / "p.policy", table, env=env, trainer_steps=args.steps, seed=1)
            policy = zumo_swarm.load_policy(path)
            exported = host_formations(args.host, path, args.steps, 1) if args.host else None
        result = evaluate(policy.act, e)
        rows.append({"learner": name, "reward": reward, "steps": args.steps, "trained_formations": trained,
                     "exported_formations": exported, **result, **cost, **(extra or {})})
        print(rows[-1], flush=True)
        load.append(os.getloadavg()[0])

    baseline("robots standing still", forward_speed=0.0)
    baseline("random actions")
    import tabular_q

    def tabular(reward, **settings):
        def train_and_table():
            q, formations, env = tabular_q.train(steps=args.steps, seed=1, reward=reward, **settings)
            return q, int(formations), env
        return train_and_table

    for reward in args.tabular_rewards:
        learned("tabular Q (tabular_q.py)", reward, tabular(reward))
    for initial_q, epsilon in args.tabular_exploration:
        learned(f"tabular Q (tabular_q.py), initial Q {initial_q:g}, epsilon {epsilon:g}", "reference",
                tabular("reference", initial_q=initial_q, epsilon=epsilon))
    if args.neural:
        import marl_ppo

        for reward in args.marl_rewards:
            def marl(reward=reward):
                a = marl_ppo.parse(["--steps", str(args.steps), "--reward", reward, "--seed", "1"])
                agent, env, log = marl_ppo.train(a)
                return agent.table(), log["formations"], env
            learned("shared-policy PPO (marl_ppo.py)", reward, marl)
        if args.sb3_rewards:  # stable-baselines3 only where its rows are asked for
            import ppo_sb3
        for reward in args.sb3_rewards:
            def sb3(reward=reward):
                _, env, table = ppo_sb3.train(steps=args.steps, seed=1, reward=reward)
                return table, env.venv.formations, env.venv.venv
            learned("SB3 PPO (ppo_sb3.py)", reward, sb3)
        import marl_q

        for reward in args.marl_q_rewards:
            def shared_q(reward=reward):
                a = marl_q.parse(["--steps", str(args.steps), "--reward", reward, "--seed", "1"])
                q, env, log = marl_q.train(a)
                return log["selected"], log["formations"], env
            learned("shared Q-network (marl_q.py)", reward, shared_q)
    return {
        "date": datetime.date.today().isoformat(),
        "machine": f"{platform.machine()}, {os.cpu_count()} cores",
        "load_average": [round(x, 1) for x in load],
        "budget_steps": args.steps,
        "eval_seeds": EVAL_SEEDS,
        "eval_steps": e,
        "rows": rows,
    }


def render(results: dict) -> str:
    """The markdown table of docs/python-results.md."""
    head = (
        f"Measured {results['date']} on {results['machine']} (1-minute load average {', '.join(map(str, results['load_average']))}), "
        f"{results['budget_steps']:,} world-steps of training each, seed 1; every policy then run greedily for "
        f"{results['eval_steps']:,} steps on each of {len(results['eval_seeds'])} evaluation seeds "
        f"({results['eval_seeds'][0]} to {results['eval_seeds'][-1]}).\n\n"
        "| learner | reward | formed while training | exported blob, `host run` same steps | formed on the evaluation seeds | final Eval (mean of seeds) | mean Eval at checks | training time (s) |\n"
        "|---|---|---|---|---|---|---|---|\n"
    )
    show = lambda v: "" if v is None else str(v)
    lines = [
        f"| {r['learner']} | {show(r['reward'])} | {show(r['trained_formations'])} | {show(r['exported_formations'])} | "
        f"{r['formations']} | {r['final_eval']:.4f} | {r['mean_eval']:.4f} | {r['seconds'] if r['steps'] else ''} |"
        for r in results["rows"]
    ]
    return head + "\n".join(lines) + "\n"


def exploration(text: str) -> tuple[float, float]:
    """An `--tabular-exploration` pair: initial Q-value and epsilon."""
    try:
        initial_q, epsilon = (float(x) for x in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not INITIAL_Q,EPSILON (two numbers, e.g. 1,0.1)") from None
    if not 0.0 <= epsilon <= 1.0:
        raise argparse.ArgumentTypeError(f"epsilon {epsilon} in {text!r} is not between 0 and 1")
    return initial_q, epsilon


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--render", metavar="JSON")
    p.add_argument("--steps", type=int, default=200_000, help="training budget, world-steps")
    p.add_argument("--eval-steps", type=int, default=20_000)
    p.add_argument("--host", help="the host binary, to run each exported blob as a robot would")
    p.add_argument("--tabular-rewards", nargs="*", default=["reference", "thesis", "success-shaped"])
    p.add_argument("--marl-rewards", nargs="*", default=["reference", "per-robot", "success-shaped"])
    p.add_argument("--sb3-rewards", nargs="*", default=["reference"])
    p.add_argument("--marl-q-rewards", nargs="*", default=["reference"])
    p.add_argument("--tabular-exploration", action="append", default=[], type=exploration, metavar="INITIAL_Q,EPSILON",
                   help="a tabular Q-learning row (reference reward) with another initial value or exploration; "
                        "repeatable, written with = for a negative value (--tabular-exploration=-10,0)")
    p.add_argument("--no-neural", dest="neural", action="store_false")
    p.add_argument("--out", default="docs/python-learning.json")
    args = p.parse_args()
    results_file.render_or_measure(args, run, render)


if __name__ == "__main__":
    main()
