"""Multi-agent PPO in the style of CleanRL (one file, PyTorch): one policy
shared by every robot of every world, over the vector env.

Each robot sees its own hashed state (observation="state"), so the trained
policy is a table: its greedy action for each state, exported as a policy
blob that `host run --controller policy:FILE` and `host flash` take.

Exploration is consistent in time: each world acts on its own draw of the
policy, a table drawn by the Gumbel-max trick (the argmax of the logits
plus Gumbel noise fixed per world and state), the noise redrawn every
--redraw updates. Every action is still a sample of the current policy
(for any logits, the argmax with Gumbel noise is distributed as the
softmax), so PPO's ratios are as usual; but a state's action stays the same
for hundreds of steps, as a greedy learner's does. With actions sampled
afresh at every step (--redraw 0) no setting we tried formed an annulus
(docs/python.md, "How the greedy learner explores").
"""
import argparse

import numpy as np
import torch
from torch import nn

import zumo_swarm


def parse(argv=None):
    p = argparse.ArgumentParser(description=__doc__)
    p.add_argument("--steps", type=int, default=1_000_000, help="world-steps, all worlds together")
    p.add_argument("--worlds", type=int, default=16)
    p.add_argument("--rollout", type=int, default=128, help="steps per world between updates")
    p.add_argument("--reward", default="reference")
    p.add_argument("--max-steps", type=int, default=10_000, help="episode truncation")
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--lr", type=float, default=1e-3)
    p.add_argument("--gamma", type=float, default=0.9)
    p.add_argument("--gae-lambda", type=float, default=0.9)
    p.add_argument("--epochs", type=int, default=4)
    p.add_argument("--minibatches", type=int, default=4)
    p.add_argument("--clip", type=float, default=0.2)
    p.add_argument("--ent-coef", type=float, default=0.0)
    p.add_argument("--redraw", type=int, default=5, help="updates between draws of each world's exploration noise (0: sample every step)")
    p.add_argument("--out", default="out/marl-annulus.policy")
    args = p.parse_args(argv)
    if args.redraw < 0:
        p.error(f"--redraw {args.redraw}: expected a number of updates, 0 or more")
    return args


def gumbel_noise(shape, generator=None):
    """Standard Gumbel noise: added to logits, its argmax is a sample of their softmax."""
    return -torch.log(-torch.log(torch.rand(shape, generator=generator).clamp_min(1e-12)))


class Agent(nn.Module):
    """Actor and critic over one robot's hashed state (one-hot)."""

    def __init__(self, states, actions):
        super().__init__()
        self.states = states
        self.body = nn.Sequential(nn.Linear(states, 64), nn.Tanh())
        self.actor = nn.Linear(64, actions)
        self.critic = nn.Linear(64, 1)

    def forward(self, s):
        h = self.body(nn.functional.one_hot(s, self.states).float())
        return self.actor(h), self.critic(h).squeeze(-1)

    def table(self):
        """The greedy action of every state: the policy as the robot looks it up."""
        with torch.no_grad():
            return self(torch.arange(self.states))[0].argmax(-1).numpy()


def train(args):
    torch.manual_seed(args.seed)
    torch.set_num_threads(1)  # small network: more threads only contend with the simulator's
    env = zumo_swarm.RecordRobotEpisodeStatistics(zumo_swarm.vector_env(
        args.worlds, observation="state", reward=args.reward, gamma=args.gamma,
        max_steps=args.max_steps, autoreset_mode="same-step", seed=args.seed,
    ))
    batch = env.unwrapped.batch
    agent = Agent(batch.num_states, len(batch.angular_speeds))
    optimiser = torch.optim.Adam(agent.parameters(), lr=args.lr)
    W, R, T = args.worlds, batch.robots, args.rollout
    obs = torch.as_tensor(env.reset(seed=args.seed)[0])
    log = {"episodes": [], "formations": 0}
    for update in range(max(1, args.steps // (W * T))):
        if args.redraw and update % args.redraw == 0:  # each world's draw of the policy: Gumbel noise per state
            gumbel = gumbel_noise((W, batch.num_states, len(batch.angular_speeds)))
        states, actions, logps, values = (torch.zeros((T, W, R), dtype=d) for d in (torch.long, torch.long, torch.float, torch.float))
        rewards, dones = torch.zeros((T, W, R)), torch.zeros((T, W))
        for t in range(T):
            with torch.no_grad():
                logits, value = agent(obs)
            dist = torch.distributions.Categorical(logits=logits)
            if args.redraw:
                action = (logits + gumbel[torch.arange(W)[:, None], obs]).argmax(-1)
            else:
                action = dist.sample()
            states[t], actions[t], logps[t], values[t] = obs, action, dist.log_prob(action), value
            next_obs, reward, terminated, truncated, info = env.step(action.numpy())
            rewards[t], dones[t] = torch.as_tensor(reward, dtype=torch.float), torch.as_tensor(terminated | truncated, dtype=torch.float)
            obs = torch.as_tensor(next_obs)
            if "episode" in info:
                ended = info["_episode"]
                # an ended episode's return, and its last Eval (same-step autoreset reports the ending step's)
                log["episodes"].append((float(info["episode"]["r"][ended].mean()), float(info["eval"][ended].mean())))
        log["formations"] = int(info["formations"].sum())
        with torch.no_grad():  # generalised advantage estimation, robot by robot
            next_value = agent(obs)[1]
            advantages, last = torch.zeros_like(rewards), torch.zeros((W, R))
            for t in reversed(range(T)):
                live = (1.0 - dones[t])[:, None]
                after = next_value if t == T - 1 else values[t + 1]
                delta = rewards[t] + args.gamma * after * live - values[t]
                last = delta + args.gamma * args.gae_lambda * live * last
                advantages[t] = last
            returns = advantages + values
        flat = [x.reshape(-1) for x in (states, actions, logps, advantages, returns)]
        n = flat[0].numel()
        for _ in range(args.epochs):
            for idx in torch.randperm(n).chunk(args.minibatches):
                s, a, old, adv, ret = (x[idx] for x in flat)
                logits, value = agent(s)
                dist = torch.distributions.Categorical(logits=logits)
                ratio = (dist.log_prob(a) - old).exp()
                adv = (adv - adv.mean()) / (adv.std() + 1e-8)
                policy_loss = torch.max(-adv * ratio, -adv * ratio.clamp(1 - args.clip, 1 + args.clip)).mean()
                loss = policy_loss + 0.5 * ((value - ret) ** 2).mean() - args.ent_coef * dist.entropy().mean()
                optimiser.zero_grad()
                loss.backward()
                nn.utils.clip_grad_norm_(agent.parameters(), 0.5)
                optimiser.step()
        if env.return_queue:
            print(f"update {update}: {log['formations']} formed, mean episode return {np.mean(env.return_queue):.3f}, Eval {info['eval'].mean():.4f}")
    return agent, env, log


if __name__ == "__main__":
    args = parse()
    agent, env, log = train(args)
    print(f"{log['formations']} annuli formed in {args.steps} world-steps")
    zumo_swarm.export_policy(args.out, agent.table(), env=env, trainer_steps=args.steps, seed=args.seed)
