"""The vector environment: shapes, autoreset, seeds, threads."""

import numpy as np
import pytest
from gymnasium.vector import AutoresetMode

import zumo_swarm

SMALL = {"robots": 3, "pucks": 30}


def test_arrays_have_the_worlds_and_robots_shapes():
    env = zumo_swarm.vector_env(6, **SMALL)
    obs, _ = env.reset(seed=1)
    assert obs.shape == (6, 3, 7) and obs.dtype == np.float32
    assert env.observation_space.shape == (6, 3, 7) and env.single_observation_space.shape == (3, 7)
    assert env.action_space.shape == (6, 3)
    obs, rewards, terminated, truncated, info = env.step(env.action_space.sample())
    assert obs.shape == (6, 3, 7) and rewards.shape == (6, 3) and rewards.dtype == np.float64
    assert terminated.shape == truncated.shape == (6,) and terminated.dtype == bool
    assert (rewards == rewards[:, :1]).all(), "every robot of a world gets the world's reward"
    for key in ["eval", "episode_step", "robot_contacts", "formations", "stuck_episodes", "mean_eval", "reset"]:
        assert info[key].shape == (6,) and info["_" + key].all()
    states = zumo_swarm.vector_env(2, observation="state", hasher="bits9", **SMALL)
    obs, _ = states.reset()
    assert obs.shape == (2, 3) and obs.dtype == np.int64 and (obs < 512).all()


def test_next_step_autoreset_is_the_default_and_resets_on_the_step_after_the_end():
    env = zumo_swarm.vector_env(2, max_steps=4, **SMALL)
    assert env.metadata["autoreset_mode"] == AutoresetMode.NEXT_STEP
    assert "next-step" in zumo_swarm.vector_env.__doc__ and "next-step" in type(env).__doc__
    env.reset(seed=1)
    actions = np.ones((2, 3), dtype=np.int64)
    for step in range(1, 5):
        _, _, terminated, truncated, info = env.step(actions)
        assert (info["episode_step"] == step).all()
    assert truncated.all() and not terminated.any()
    first = zumo_swarm.vector_env(2, **SMALL).reset(seed=1)[0]
    obs, rewards, terminated, truncated, info = env.step(actions)
    assert info["reset"].all() and (rewards == 0).all() and not (terminated | truncated).any()
    assert (info["episode_step"] == 0).all()
    assert not np.array_equal(obs, first), "the new episode starts from new positions"
    _, _, _, _, info = env.step(actions)
    assert (info["episode_step"] == 1).all()


def test_same_step_autoreset_returns_the_new_episode_and_the_last_observation_in_infos():
    same = zumo_swarm.vector_env(2, max_steps=3, autoreset_mode="same-step", **SMALL)
    nxt = zumo_swarm.vector_env(2, max_steps=3, **SMALL)
    same.reset(seed=9), nxt.reset(seed=9)
    actions = np.zeros((2, 3), dtype=np.int64)
    for _ in range(2):
        same.step(actions), nxt.step(actions)
    obs, _, _, truncated, info = same.step(actions)
    last, *_ = nxt.step(actions)
    assert truncated.all() and info["_final_obs"].all()
    assert np.array_equal(info["final_obs"], last)
    assert np.array_equal(obs, nxt.step(actions)[0])


def test_threads_do_not_change_the_trajectories_and_seeds_go_world_by_world():
    runs = []
    for threads in [1, 2]:
        env = zumo_swarm.vector_env(5, threads=threads, max_steps=50, **SMALL)
        env.reset(seed=20)
        rng = np.random.default_rng(3)
        out = [env.step(rng.integers(0, 4, (5, 3)))[:4] for _ in range(120)]
        runs.append(out)
    for a, b in zip(*runs):
        for x, y in zip(a, b):
            assert np.array_equal(x, y)
    env = zumo_swarm.vector_env(3, **SMALL)
    obs, _ = env.reset(seed=20)
    single = zumo_swarm.gym_env(**SMALL)
    for i in range(3):
        assert np.array_equal(obs[i], single.reset(seed=20 + i)[0])
    obs, _ = env.reset(seed=[7, 7, 8])
    assert np.array_equal(obs[0], obs[1]) and not np.array_equal(obs[0], obs[2])


def test_the_single_agent_view_has_gymnasiums_shapes():
    view = zumo_swarm.vector_env(4, **SMALL).single_agent_view()
    view.reset(seed=0)
    _, rewards, terminated, _, _ = view.step(view.action_space.sample())
    assert rewards.shape == (4,) and terminated.shape == (4,)
    import gymnasium as gym

    made = gym.make_vec("zumo_swarm/Swarm-v0", num_envs=3, vectorization_mode="vector_entry_point", **SMALL)
    assert made.num_envs == 3 and made.single_action_space == gym.spaces.MultiDiscrete([4] * 3)
    assert made.env.batch.max_steps == 150_000, "the spec's max_episode_steps truncates"


def test_continuous_actions_are_angular_speeds_clipped_to_the_table():
    env = zumo_swarm.vector_env(1, action="continuous", **SMALL)
    clipped = zumo_swarm.vector_env(1, action="continuous", **SMALL)
    discrete = zumo_swarm.vector_env(1, **SMALL)
    for e in (env, clipped, discrete):
        e.reset(seed=2)
    for _ in range(50):
        a = env.step(np.full((1, 3), 0.3))[0]
        b = clipped.step(np.full((1, 3), 5.0))[0]
        c = discrete.step(np.zeros((1, 3), dtype=np.int64))[0]  # action 0 turns by 0.3
    assert np.array_equal(a, b) and np.array_equal(a, c)


@pytest.mark.parametrize("worlds", [1, 3])
def test_render_draws_every_world(worlds):
    env = zumo_swarm.vector_env(worlds, render_mode="rgb_array", render_size=50, **SMALL)
    env.reset(seed=1)
    frames = env.render()
    assert len(frames) == worlds and frames[0].shape == (50, 50, 3)
