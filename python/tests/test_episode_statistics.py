"""Episode statistics: every vector env this package offers works with
Gymnasium's RecordEpisodeStatistics (or, for the per-robot env, with the
package's wrapper over it), and reports the returns the steps summed to."""

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.wrappers.vector import RecordEpisodeStatistics

import zumo_swarm

SMALL = {"robots": 3, "pucks": 30, "max_steps": 5}


def _summed_returns(env, steps, robots_axis):
    """Steps ``env`` with fixed random actions; returns the episode
    statistics it reported and the returns summed from its rewards."""
    env.reset(seed=4)
    rng = np.random.default_rng(0)
    reported, summed = [], []
    running = np.zeros(env.num_envs)
    fresh = np.zeros(env.num_envs, dtype=bool)
    for _ in range(steps):
        _, rewards, terminated, truncated, info = env.step(rng.integers(0, 4, (env.num_envs, 3)))
        world_rewards = rewards.mean(axis=1) if robots_axis else rewards
        running[fresh] = 0.0  # next-step autoreset: this step only reset these worlds
        running[~fresh] += world_rewards[~fresh]
        done = terminated | truncated
        if done.any():
            assert info["_episode"].tolist() == done.tolist()
            reported.extend(info["episode"]["r"][done])
            summed.extend(running[done])
            assert (info["episode"]["l"][done] == 5).all()
        fresh = done
    return reported, summed


@pytest.mark.parametrize("make", [
    lambda: zumo_swarm.vector_env(4, **SMALL).single_agent_view(),
    lambda: gym.make_vec("zumo_swarm/Swarm-v0", num_envs=4, vectorization_mode="vector_entry_point", **SMALL),
], ids=["single_agent_view", "make_vec"])
def test_gymnasiums_record_episode_statistics_reports_the_summed_returns_of_the_single_agent_view(make):
    env = RecordEpisodeStatistics(make())
    reported, summed = _summed_returns(env, 24, robots_axis=False)
    assert len(reported) == 16 and env.episode_count == 16
    assert np.allclose(reported, summed)
    assert len(env.return_queue) == 16


def test_the_per_robot_vector_env_needs_the_packages_wrapper_which_reports_the_summed_returns():
    raw = RecordEpisodeStatistics(zumo_swarm.vector_env(4, **SMALL))
    with pytest.raises(TypeError, match="RecordEpisodeStatistics cannot wrap zumo_swarm.vector_env"):
        raw.reset(seed=1)
    env = zumo_swarm.RecordRobotEpisodeStatistics(zumo_swarm.vector_env(4, **SMALL))
    reported, summed = _summed_returns(env, 24, robots_axis=True)
    assert len(reported) == 16 and env.episode_count == 16 and len(env.return_queue) == 16
    assert np.allclose(reported, summed)
    _, rewards, *_ = env.step(np.zeros((4, 3), dtype=np.int64))
    assert rewards.shape == (4, 3), "the wrapper leaves the per-robot rewards as they are"


def test_same_step_autoreset_counts_every_step_toward_an_episode():
    env = zumo_swarm.RecordRobotEpisodeStatistics(zumo_swarm.vector_env(2, autoreset_mode="same-step", **SMALL))
    env.reset(seed=2)
    total = np.zeros(2)
    for step in range(1, 11):
        _, rewards, terminated, truncated, info = env.step(np.ones((2, 3), dtype=np.int64))
        total += rewards.mean(axis=1)
        if step % 5 == 0:
            assert truncated.all() and np.allclose(info["episode"]["r"], total)
            assert (info["episode"]["l"] == 5).all()
            total[:] = 0.0
        else:
            assert "episode" not in info


def test_sb3s_vec_monitor_logs_episode_returns_and_eval_of_the_adapter():
    pytest.importorskip("stable_baselines3")
    from stable_baselines3.common.vec_env import VecMonitor

    from zumo_swarm.sb3 import SB3VecEnv

    env = VecMonitor(SB3VecEnv(2, **SMALL), info_keywords=("eval",))
    env.reset()
    episodes = []
    for _ in range(10):
        _, _, dones, infos = env.step(np.ones((2, 3), dtype=np.int64))
        episodes += [info["episode"] for info, done in zip(infos, dones) if done]
    assert len(episodes) == 4 and all(e["l"] == 5 and 0.0 <= e["eval"] <= 1.0 for e in episodes)
