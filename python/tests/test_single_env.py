"""The single-agent Gymnasium view of one world."""

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import zumo_swarm


@pytest.mark.parametrize(
    "settings",
    [{}, {"observation": "state"}, {"action": "continuous"}, {"sensors": "robot", "robots": 4, "pucks": 80}],
    ids=["readings", "states", "continuous", "robot-sensors"],
)
def test_gymnasiums_environment_checker_passes(settings):
    env = gym.make("zumo_swarm/Swarm-v0", render_mode="rgb_array", render_size=64, **settings)
    check_env(env.unwrapped, skip_render_check=False)


def test_the_view_stacks_every_robot_and_acts_for_all():
    env = zumo_swarm.gym_env(robots=5, pucks=40, observation="state")
    assert env.observation_space == gym.spaces.MultiDiscrete([256] * 5)
    assert env.action_space == gym.spaces.MultiDiscrete([4] * 5)
    obs, _ = env.reset(seed=2)
    assert obs.shape == (5,) and env.observation_space.contains(obs)
    obs, reward, terminated, truncated, info = env.step(np.array([0, 1, 2, 3, 0]))
    assert isinstance(reward, float) and terminated is False and truncated is False
    assert info["episode_step"] == 1


def test_the_same_seed_gives_the_same_trajectory_and_another_seed_another():
    def trajectory(seed):
        env = zumo_swarm.gym_env(robots=4, pucks=60)
        obs, _ = env.reset(seed=seed)
        rng = np.random.default_rng(0)
        out = [obs]
        for _ in range(300):
            obs, reward, *_ = env.step(rng.integers(0, 4, 4))
            out.append(obs)
        return np.array(out), env.positions()[0]

    (a, pa), (b, pb), (c, pc) = trajectory(5), trajectory(5), trajectory(6)
    assert np.array_equal(a, b) and np.array_equal(pa, pb)
    assert not np.array_equal(pa, pc)


def test_reset_without_a_seed_starts_a_new_episode_of_the_same_stream():
    env = zumo_swarm.gym_env(robots=3, pucks=20, seed=4)
    first, _ = env.reset()
    again, _ = env.reset(seed=4)
    assert np.array_equal(first, again), "the constructor's seed is the first episode's"
    env.step(np.zeros(3, dtype=np.int64))
    env.reset()
    assert not np.array_equal(env.positions()[0], zumo_swarm.gym_env(robots=3, pucks=20, seed=4).positions()[0])


def test_every_reset_starts_a_new_episode_unless_given_the_same_seed():
    env = zumo_swarm.gym_env(robots=3, pucks=20, seed=4)
    env.reset()
    first = env.positions()[0]
    env.reset()
    second = env.positions()[0]
    assert not np.array_equal(first, second), "reset(); reset() gives two episodes"
    env.reset(seed=4)
    assert np.array_equal(env.positions()[0], first), "the same seed, the same episode"
    env.reset()
    assert not np.array_equal(env.positions()[0], first)


def test_the_registered_environment_truncates_at_the_default_stuck_limit():
    import gymnasium

    assert gymnasium.spec("zumo_swarm/Swarm-v0").max_episode_steps == 150_000
