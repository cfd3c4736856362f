"""PPO (Stable-Baselines3) on the single-agent view: one network acts for every robot of a world.

The robots' hashed states are the input (observation="state"). The actor is shared by the robots:
each robot's action comes from its own state alone, through the same layers, so the trained policy
is a table over hashed states, exactly what a robot looks up; the critic sees every robot's features
(the reward is the world's). Exploration is consistent in time, as in marl_ppo.py: each world acts
on its own draw of the policy (Gumbel noise fixed per world, robot and state), redrawn every few
rollouts; SB3 would sample every discrete action afresh, which learns nothing here (docs/python-results.md).
VecMonitor measures each episode's return and last Eval; they are logged as CleanRL logs them, with
each evaluation, to out/runs/RUN/scalars.csv and to TensorBoard when it is installed (run_log.py), and SB3
prints its table every rollout. Every 100,000 steps the greedy table runs on one evaluation world, and
the table that formed most there is the one exported as a policy blob (as marl_q.py and `host train
--select-every` keep their best). The run ends with a summary that holds the held-out evaluation: the
exported table run greedily on the evaluation seeds, none of them trained or selected on.
"""
import argparse

import numpy as np
import torch
from stable_baselines3 import PPO
from stable_baselines3.common.callbacks import BaseCallback
from stable_baselines3.common.policies import ActorCriticPolicy
from stable_baselines3.common.torch_layers import BaseFeaturesExtractor
from stable_baselines3.common.vec_env import VecMonitor
from torch import nn

import zumo_swarm
from marl_ppo import gumbel_noise
from marl_q import greedy_formations
from run_log import RunLog, held_out
from zumo_swarm.sb3 import SB3VecEnv


class PerRobot(BaseFeaturesExtractor):
    """Each robot's one-hot state through the same layer: the robots' features side by side."""

    def __init__(self, observation_space, hidden=64):
        self.robots, self.states, self.hidden = len(observation_space.nvec), int(observation_space.nvec[0]), hidden
        super().__init__(observation_space, self.robots * hidden)
        self.body = nn.Sequential(nn.Linear(self.states, hidden), nn.Tanh())

    def forward(self, one_hot):
        return self.body(one_hot.view(len(one_hot), self.robots, self.states)).flatten(1)


class SharedHead(nn.Module):
    """Every robot's action logits from its own features, by the same layer."""

    def __init__(self, robots, hidden, actions):
        super().__init__()
        self.robots, self.hidden = robots, hidden
        self.linear = nn.Linear(hidden, actions)

    def forward(self, features):
        return self.linear(features.view(len(features), self.robots, self.hidden)).flatten(1)


class SharedRobotPolicy(ActorCriticPolicy):
    """SB3's actor-critic with the actor shared by the robots and each world's own draw of it."""

    noise = None  # Gumbel noise per world, robot, state and action (Redraw sets it)

    def __init__(self, *args, **kwargs):
        super().__init__(*args, features_extractor_class=PerRobot, net_arch=dict(pi=[], vf=[]), ortho_init=False, **kwargs)

    def _build(self, lr_schedule):
        super()._build(lr_schedule)
        f = self.features_extractor
        self.action_net = SharedHead(f.robots, f.hidden, int(self.action_space.nvec[0]))
        self.optimizer = self.optimizer_class(self.parameters(), lr=lr_schedule(1), **self.optimizer_kwargs)

    def forward(self, obs, deterministic=False):
        if deterministic or self.noise is None or len(obs) != len(self.noise):
            return super().forward(obs, deterministic)
        latent_pi, latent_vf = self.mlp_extractor(self.extract_features(obs))
        distribution = self._get_action_dist_from_latent(latent_pi)
        logits = torch.stack([d.logits for d in distribution.distribution], dim=1)
        worlds, robots = torch.arange(len(obs))[:, None], torch.arange(obs.shape[1])[None, :]
        # the argmax with Gumbel noise is a sample of the softmax, held while the noise is
        actions = (logits + self.noise[worlds, robots, obs.long()]).argmax(-1)
        return actions, self.value_net(latent_vf), distribution.log_prob(actions)

    def table(self):
        """The greedy action of every state: the policy as the robot looks it up."""
        with torch.no_grad():
            body, head = self.features_extractor.body, self.action_net.linear
            return head(body(torch.eye(self.features_extractor.states))).argmax(-1).numpy()


class Redraw(BaseCallback):
    """Draws each world's exploration noise anew every `every` rollouts."""

    def __init__(self, every, seed):
        super().__init__()
        self.every, self.rollouts, self.generator = every, 0, torch.Generator().manual_seed(seed)

    def _on_step(self):
        return True

    def _on_rollout_start(self):
        if self.rollouts % self.every == 0:
            policy, space = self.model.policy, self.model.action_space
            shape = (self.training_env.num_envs, len(space.nvec), policy.features_extractor.states, int(space.nvec[0]))
            policy.noise = gumbel_noise(shape, self.generator)
        self.rollouts += 1


class SelectTable(BaseCallback):
    """Every `every` steps and at the end, runs the greedy table for `steps` steps on the evaluation
    world of `seed`; `selected` is the table that formed most there (the earliest of equals)."""

    def __init__(self, every, steps, seed, log=None):
        super().__init__()
        self.every, self.steps, self.seed, self.checks, self.log = every, steps, seed, 0, log
        self.selected, self.formed = None, -1

    def _on_step(self):
        return True

    def _judge(self):
        table = self.model.policy.table()
        formed = greedy_formations(table, self.seed, self.steps)
        if self.log:
            self.log.scalar("eval/selection_formations", formed, self.num_timesteps)
        if formed > self.formed:
            self.selected, self.formed = table, formed

    def _on_rollout_end(self):
        if self.num_timesteps // self.every > self.checks:
            self.checks = self.num_timesteps // self.every
            self._judge()

    def _on_training_end(self):
        self._judge()


class LogEval(BaseCallback):
    """Logs the mean last Eval of the recent episodes beside SB3's mean return."""

    def _on_step(self):
        return True

    def _on_rollout_end(self):
        evals = [e["eval"] for e in self.model.ep_info_buffer if "eval" in e]
        if evals:
            self.logger.record("rollout/ep_eval_mean", float(np.mean(evals)))


class LogEpisodes(BaseCallback):
    """Logs each ended episode's return, length and last Eval as CleanRL does."""

    def __init__(self, log):
        super().__init__()
        self.log = log

    def _on_step(self):
        for info in self.locals["infos"]:
            if "episode" in info:
                for key, tag in [("r", "episodic_return"), ("l", "episodic_length"), ("eval", "episodic_eval")]:
                    self.log.scalar(f"charts/{tag}", info["episode"][key], self.num_timesteps)
        return True


def train(steps=1_000_000, seed=1, reward="reference", worlds=16, max_steps=10_000, gamma=0.9, redraw=5,
          select_every=100_000, select_steps=50_000, log=None):
    """The trained model, its env and the selected greedy table (`log`: a run_log.RunLog, or None)."""
    torch.set_num_threads(1)  # small network: more threads only contend with the simulator's
    env = VecMonitor(
        SB3VecEnv(worlds, observation="state", reward=reward, gamma=gamma, max_steps=max_steps, seed=seed),
        info_keywords=("eval",),
    )
    model = PPO(SharedRobotPolicy, env, n_steps=128, batch_size=512, n_epochs=4, learning_rate=1e-3,
                gamma=gamma, gae_lambda=0.9, verbose=1, seed=seed)
    select = SelectTable(select_every, select_steps, seed + 1_000_000, log)  # no training world's seed
    callbacks = [LogEval(), Redraw(redraw, seed), select] + ([LogEpisodes(log)] if log else [])
    model.learn(total_timesteps=steps, callback=callbacks)
    return model, env, select.selected


def main(argv=None):
    """Trains, exports the selected table, evaluates it on the held-out seeds and prints the summary."""
    p = argparse.ArgumentParser(description=__doc__)
    p.add_argument("steps", nargs="?", type=int, default=1_000_000, help="world-steps, all worlds together")
    p.add_argument("--out", default="out/ppo-annulus.policy")
    p.add_argument("--eval-steps", type=int, default=20_000, help="steps of the held-out evaluation on each seed")
    p.add_argument("--run-dir", help="the log's directory (default out/runs/ppo_sb3__1__TIME)")
    args = p.parse_args(argv)
    log = RunLog("ppo_sb3", {**vars(args), "seed": 1}, args.run_dir)
    model, env, table = train(args.steps, log=log)
    seconds = log.seconds()
    path = zumo_swarm.export_policy(args.out, table, env=env.venv.venv, trainer_steps=args.steps, seed=1)
    summary = {
        "trained": f"{args.steps:,} world-steps in {seconds:.1f} s, reward reference, seed 1",
        "while training": f"{env.venv.formations} formations, mean return of the last {len(model.ep_info_buffer)} "
        f"episodes {np.mean([e['r'] for e in model.ep_info_buffer] or [np.nan]):.3f}",
        "held-out evaluation": held_out(zumo_swarm.load_policy(path).act, args.eval_steps, log, args.steps),
        "policy": str(path),
    }
    log.finish(summary)
    return summary


if __name__ == "__main__":
    main()
