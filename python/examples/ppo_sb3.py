"""PPO (Stable-Baselines3) on the single-agent view: one network acts for every robot of a world.

The robots' hashed states are the input (observation="state"), VecMonitor logs each episode's return
and last Eval (add tensorboard_log="runs" to PPO for TensorBoard), and the network is distilled into a
table, each state's action as the network chooses it for the robots in that state, exported as a
policy blob.
"""
import sys
from collections import Counter

import numpy as np
import torch
from stable_baselines3 import PPO
from stable_baselines3.common.callbacks import BaseCallback
from stable_baselines3.common.vec_env import VecMonitor

import zumo_swarm
from zumo_swarm.sb3 import SB3VecEnv


class LogEval(BaseCallback):
    """Logs the mean last Eval of the recent episodes beside SB3's mean return."""

    def _on_step(self):
        return True

    def _on_rollout_end(self):
        evals = [e["eval"] for e in self.model.ep_info_buffer if "eval" in e]
        if evals:
            self.logger.record("rollout/ep_eval_mean", float(np.mean(evals)))


def train(steps=1_000_000, seed=1, reward="success-shaped", worlds=16, max_steps=10_000):
    torch.set_num_threads(1)  # small network: more threads only contend with the simulator's
    env = VecMonitor(
        SB3VecEnv(worlds, observation="state", reward=reward, gamma=0.99, max_steps=max_steps, seed=seed),
        info_keywords=("eval",),
    )
    model = PPO("MlpPolicy", env, n_steps=128, batch_size=512, learning_rate=3e-4, gamma=0.99, verbose=1, seed=seed)
    model.learn(total_timesteps=steps, callback=LogEval())
    return model, env


def distil(model, env, steps=2_000, seed=1):
    """The network as a table over hashed states: for each state the
    robots met while the network acted greedily, the action it chose most
    often for a robot in that state; for every other state, its choice for
    a world whose robots are all in that state."""
    venv = env.venv.venv  # the vector env under VecMonitor and the SB3 adapter
    batch = venv.batch
    votes = [Counter() for _ in range(batch.num_states)]
    obs, _ = venv.reset(seed=seed)
    for _ in range(steps):
        actions, _ = model.predict(obs, deterministic=True)
        for s, a in zip(obs.reshape(-1), actions.reshape(-1)):
            votes[s][a] += 1
        obs, *_ = venv.step(actions)
    alike, _ = model.predict(np.repeat(np.arange(batch.num_states)[:, None], batch.robots, axis=1), deterministic=True)
    return np.array([v.most_common(1)[0][0] if v else alike[s, 0] for s, v in enumerate(votes)])


if __name__ == "__main__":
    steps = int(sys.argv[1]) if len(sys.argv) > 1 else 1_000_000
    model, env = train(steps)
    zumo_swarm.export_policy("out/ppo-annulus.policy", distil(model, env), env=env.venv.venv, trainer_steps=steps, seed=1)
