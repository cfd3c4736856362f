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
(docs/python-results.md, "How the greedy learner explores").

It prints a line every update, logs as CleanRL does (each ended episode's
return, length and last Eval, the losses and steps per second, to
out/runs/RUN/scalars.csv and to TensorBoard when it is installed: run_log.py),
and ends with a summary that holds the held-out evaluation: the exported
table run greedily on the evaluation seeds, none of them trained on.
"""
import argparse
import time

import numpy as np
import torch
from torch import nn

import zumo_swarm
from run_log import RunLog, held_out


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
    p.add_argument("--eval-steps", type=int, default=20_000, help="steps of the held-out evaluation on each evaluation seed")
    p.add_argument("--run-dir", help="the log's directory (default out/runs/marl_ppo__SEED__TIME)")
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


def train(args, log=None):
    """The trained agent, its env and what it logged (``log``: a
    :class:`run_log.RunLog`, or None to log nothing but the printed lines)."""
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
    record = {"episodes": [], "formations": 0}
    scalar = log.scalar if log else lambda *_: None
    updates, start = max(1, args.steps // (W * T)), time.perf_counter()
    for update in range(updates):
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
                record["episodes"].append((float(info["episode"]["r"][ended].mean()), float(info["eval"][ended].mean())))
                step = (update * T + t + 1) * W
                for world in np.flatnonzero(ended):
                    scalar("charts/episodic_return", info["episode"]["r"][world], step)
                    scalar("charts/episodic_length", info["episode"]["l"][world], step)
                    scalar("charts/episodic_eval", info["eval"][world], step)
        record["formations"] = int(info["formations"].sum())
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
                value_loss, entropy = 0.5 * ((value - ret) ** 2).mean(), dist.entropy().mean()
                loss = policy_loss + value_loss - args.ent_coef * entropy
                optimiser.zero_grad()
                loss.backward()
                nn.utils.clip_grad_norm_(agent.parameters(), 0.5)
                optimiser.step()
        step, sps = (update + 1) * T * W, (update + 1) * T * W / (time.perf_counter() - start)
        with torch.no_grad():  # the last minibatch's, as CleanRL logs them
            approx_kl = ((ratio - 1) - (ratio.log())).mean().item()
            clipfrac = ((ratio - 1.0).abs() > args.clip).float().mean().item()
        for tag, value in [("losses/policy_loss", policy_loss.item()), ("losses/value_loss", value_loss.item()),
                           ("losses/entropy", entropy.item()), ("losses/approx_kl", approx_kl),
                           ("losses/clipfrac", clipfrac), ("charts/formations", record["formations"]),
                           ("charts/eval", info["eval"].mean()), ("charts/SPS", sps)]:
            scalar(tag, value, step)
        returns_so_far = f"{np.mean(env.return_queue):.3f}" if env.return_queue else "none ended yet"
        print(f"update {update + 1}/{updates}, step {step:,}: {record['formations']} formed, "
              f"mean episode return {returns_so_far}, Eval {info['eval'].mean():.4f}, {sps:,.0f} steps/s", flush=True)
    return agent, env, record


def main(argv=None):
    """Trains, exports the greedy table, evaluates it on the held-out seeds
    and prints the summary; returns the summary."""
    args = parse(argv)
    log = RunLog("marl_ppo", vars(args), args.run_dir)
    agent, env, record = train(args, log)
    seconds = log.seconds()
    path = zumo_swarm.export_policy(args.out, agent.table(), env=env, trainer_steps=args.steps, seed=args.seed)
    evaluation = held_out(zumo_swarm.load_policy(path).act, args.eval_steps, log, args.steps)
    summary = {
        "trained": f"{args.steps:,} world-steps in {seconds:.1f} s, reward {args.reward}, seed {args.seed}",
        "while training": f"{record['formations']} formations, {env.episode_count} episodes ended"
        + (f", mean return of the last {len(env.return_queue)} {np.mean(env.return_queue):.3f}" if env.return_queue else ""),
        "held-out evaluation": evaluation,
        "policy": str(path),
    }
    log.finish(summary)
    return summary


if __name__ == "__main__":
    main()
