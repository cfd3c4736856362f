"""Shared-network Q-learning in the style of CleanRL (one file, PyTorch):
one Q-network for every robot of every world, over the vector env.

The thesis' learner as a PyTorch module trained by gradient steps: each
robot's hashed state (observation="state") goes in one-hot, every robot
acts greedily on the shared Q-values (ties broken at random), and after
each step one SGD step moves Q(s, a) of every robot's transition towards
r + gamma max Q(s', .); the transitions of all robots of all worlds are
the batch (no replay buffer, no target network). The loss is summed over
the batch, so each transition moves its own Q-value by --lr of its error,
as the thesis' alpha does. The network is linear in the one-hot state
with every weight at --initial-q, above what the reference reward pays: an
action not yet tried looks better than one that failed, the optimism the
thesis' learner explores by. (Through a hidden layer what one state
learns would move every other state's values too and undo that optimism.)
Every --select-every world-steps the table is frozen and run greedily on
one evaluation world (the same world each time) for --select-steps steps;
the table that forms most there (the earliest of equals) is the one it
exports, as `host train --select-every` keeps its best policy: the table
of the last step need not be the best the learner passed through. It
exports the Q-table: each state's best actions, among which the robot
picks as the learner did.

It logs as CleanRL does (each ended episode's return, length and last
Eval, each evaluation, to out/runs/RUN/scalars.csv and to TensorBoard when it
is installed: run_log.py) and ends with a summary that holds the held-out
evaluation: the exported table run greedily on the evaluation seeds, none
of them trained on (nor the world it selects on).
"""
import argparse

import numpy as np
import torch
from torch import nn

import zumo_swarm
from run_log import RunLog, held_out


def parse(argv=None):
    p = argparse.ArgumentParser(description=__doc__)
    p.add_argument("--steps", type=int, default=1_000_000, help="world-steps, all worlds together")
    p.add_argument("--worlds", type=int, default=4)
    p.add_argument("--reward", default="reference")
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--lr", type=float, default=0.2, help="SGD step size: the thesis' alpha")
    p.add_argument("--gamma", type=float, default=0.9)
    p.add_argument("--initial-q", type=float, default=1.0)
    p.add_argument("--select-every", type=int, default=100_000, help="world-steps between evaluations of the greedy table")
    p.add_argument("--select-steps", type=int, default=50_000, help="steps of each evaluation")
    p.add_argument("--max-steps", type=int, help="episode truncation (default none: an episode ends when it forms or is stuck)")
    p.add_argument("--out", default="out/marl-q-annulus.policy")
    p.add_argument("--eval-steps", type=int, default=20_000, help="steps of the held-out evaluation on each evaluation seed")
    p.add_argument("--run-dir", help="the log's directory (default out/runs/marl_q__SEED__TIME)")
    return p.parse_args(argv)


class QNetwork(nn.Module):
    """Q-values of every action for one robot's hashed state."""

    def __init__(self, states, actions, initial_q):
        super().__init__()
        self.states = states
        self.linear = nn.Linear(states, actions, bias=False)
        with torch.no_grad():
            self.linear.weight.fill_(initial_q)

    def forward(self, s):
        return self.linear(nn.functional.one_hot(s, self.states).float())

    def values(self):
        """The Q-table, states x actions: what `export_policy` turns into the
        robot's policy (every best action of a state kept, as the learner
        broke ties among them)."""
        with torch.no_grad():
            return self(torch.arange(self.states)).numpy()


def greedy(q, generator):
    """The best action of each row, ties broken uniformly at random."""
    best = q == q.max(-1, keepdim=True).values
    return torch.where(best, torch.rand(q.shape, generator=generator), -1.0).argmax(-1)


def greedy_formations(table, seed, steps):
    """Formations of a frozen table (one action per state) acting in a new
    world of `seed`, over `steps` steps."""
    env = zumo_swarm.vector_env(1, observation="state", seed=seed)
    obs, _ = env.reset(seed=seed)
    for _ in range(steps):
        obs, _, _, _, info = env.step(table[obs])
    return int(info["formations"][0])


def train(args, log=None):
    """The Q-network, its env and what it logged (``log``: a
    :class:`run_log.RunLog`, or None to log nothing but the printed lines)."""
    torch.manual_seed(args.seed)
    torch.set_num_threads(1)  # small network: more threads only contend with the simulator's
    generator = torch.Generator().manual_seed(args.seed)
    env = zumo_swarm.RecordRobotEpisodeStatistics(zumo_swarm.vector_env(
        args.worlds, observation="state", reward=args.reward, gamma=args.gamma,
        max_steps=args.max_steps, autoreset_mode="same-step", seed=args.seed,
    ))
    batch = env.unwrapped.batch
    q = QNetwork(batch.num_states, len(batch.angular_speeds), args.initial_q)
    optimiser = torch.optim.SGD(q.parameters(), lr=args.lr)
    obs = torch.as_tensor(env.reset(seed=args.seed)[0])
    judge_seed = args.seed + 1_000_000  # the evaluation world's: no training world's
    record = {"formations": 0, "episodes": [], "selected": q.values(), "selected_step": 0, "selected_formations": -1}
    scalar = log.scalar if log else lambda *_: None
    calls = max(1, args.steps // args.worlds)
    every = max(1, args.select_every // args.worlds)
    for call in range(calls):
        with torch.no_grad():
            action = greedy(q(obs), generator)
        next_obs, reward, terminated, truncated, info = env.step(action.numpy())
        # a world that ended restarted in this step: bootstrap from its final state
        after = next_obs
        if "final_obs" in info:
            after = np.where(info["_final_obs"][:, None], info["final_obs"], next_obs)
        with torch.no_grad():
            target = torch.as_tensor(reward, dtype=torch.float) + args.gamma * q(torch.as_tensor(after)).max(-1).values
        chosen = q(obs).gather(-1, action[..., None]).squeeze(-1)
        loss = 0.5 * ((chosen - target) ** 2).sum()
        optimiser.zero_grad()
        loss.backward()
        optimiser.step()
        obs = torch.as_tensor(next_obs)
        step = (call + 1) * args.worlds
        if "episode" in info:
            ended = info["_episode"]
            record["episodes"].append((float(info["episode"]["r"][ended].mean()), float(info["eval"][ended].mean())))
            for world in np.flatnonzero(ended):
                scalar("charts/episodic_return", info["episode"]["r"][world], step)
                scalar("charts/episodic_length", info["episode"]["l"][world], step)
                scalar("charts/episodic_eval", info["eval"][world], step)
        if (call + 1) % every == 0 or call == calls - 1:
            values = q.values()
            formed = greedy_formations(values.argmax(-1), judge_seed, args.select_steps)  # the lowest of equal actions
            scalar("eval/selection_formations", formed, step)
            if formed > record["selected_formations"]:
                record.update(selected=values, selected_step=step, selected_formations=formed)
            print(f"step {step}: the greedy table formed {formed} on the selection world "
                  f"(best so far: {record['selected_formations']}, of step {record['selected_step']})", flush=True)
        if call % 25_000 == 0 or call == calls - 1:
            record["formations"] = int(info["formations"].sum())
            scalar("charts/formations", record["formations"], step)
            scalar("charts/eval", info["eval"].mean(), step)
            print(f"step {step}: {record['formations']} formed, Eval {info['eval'].mean():.4f}", flush=True)
    return q, env, record


def main(argv=None):
    """Trains, exports the selected table, evaluates it on the held-out
    seeds and prints the summary; returns the summary."""
    args = parse(argv)
    log = RunLog("marl_q", vars(args), args.run_dir)
    q, env, record = train(args, log)
    seconds = log.seconds()
    path = zumo_swarm.export_policy(args.out, record["selected"], env=env, trainer_steps=args.steps, seed=args.seed)
    evaluation = held_out(zumo_swarm.load_policy(path).act, args.eval_steps, log, args.steps)
    summary = {
        "trained": f"{args.steps:,} world-steps in {seconds:.1f} s, reward {args.reward}, seed {args.seed}",
        "while training": f"{record['formations']} formations, {env.episode_count} episodes ended",
        "selected": f"the table of step {record['selected_step']:,}, {record['selected_formations']} formations "
        f"on the selection world",
        "held-out evaluation": evaluation,
        "policy": str(path),
    }
    log.finish(summary)
    return summary


if __name__ == "__main__":
    main()
