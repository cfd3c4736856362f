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
"""
import argparse

import numpy as np
import torch
from torch import nn

import zumo_swarm


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


def train(args):
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
    log = {"formations": 0, "episodes": [], "selected": q.values(), "selected_step": 0, "selected_formations": -1}
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
        if "episode" in info:
            ended = info["_episode"]
            log["episodes"].append((float(info["episode"]["r"][ended].mean()), float(info["eval"][ended].mean())))
        if (call + 1) % every == 0 or call == calls - 1:
            values = q.values()
            formed = greedy_formations(values.argmax(-1), judge_seed, args.select_steps)  # the lowest of equal actions
            if formed > log["selected_formations"]:
                log.update(selected=values, selected_step=(call + 1) * args.worlds, selected_formations=formed)
        if call % 25_000 == 0 or call == calls - 1:
            log["formations"] = int(info["formations"].sum())
            print(f"step {(call + 1) * args.worlds}: {log['formations']} formed, Eval {info['eval'].mean():.4f}")
    return q, env, log


if __name__ == "__main__":
    args = parse()
    q, env, log = train(args)
    print(f"{log['formations']} annuli formed in {args.steps} world-steps; the table of step {log['selected_step']} "
          f"formed {log['selected_formations']} on the evaluation world")
    zumo_swarm.export_policy(args.out, log["selected"], env=env, trainer_steps=args.steps, seed=args.seed)
