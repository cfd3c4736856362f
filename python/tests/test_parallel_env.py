"""The PettingZoo parallel environment."""

import numpy as np
import pytest
from pettingzoo.test import parallel_api_test

import zumo_swarm


@pytest.mark.parametrize(
    "settings",
    [
        {},
        {"observation": "state", "hasher": "original-obstacle"},
        {"action": "continuous", "robots": 3, "pucks": 40},
        {"sensors": "robot", "robots": 4, "pucks": 60},
    ],
    ids=["readings", "states", "continuous", "robot-sensors"],
)
def test_pettingzoo_parallel_api_test_passes_through_a_truncation(settings):
    env = zumo_swarm.parallel_env(max_steps=60, **settings)
    parallel_api_test(env, num_cycles=100)
    assert env.agents == [], "every agent left at the truncation"


def test_every_agent_gets_the_global_reward_and_the_world_infos():
    env = zumo_swarm.parallel_env(robots=4, pucks=50, seed=3)
    obs, _ = env.reset()
    assert sorted(obs) == ["robot_0", "robot_1", "robot_2", "robot_3"]
    assert obs["robot_0"].shape == (7,) and obs["robot_0"].dtype == np.float32
    _, rewards, terminations, truncations, infos = env.step({agent: 0 for agent in env.agents})
    assert len(set(rewards.values())) == 1
    assert not any(terminations.values()) and not any(truncations.values())
    info = infos["robot_2"]
    assert info["episode_step"] == 1 and info["total_steps"] == 1
    assert 0.0 <= info["eval"] <= 1.0
    assert {"robot_contacts", "formations", "stuck_episodes", "mean_eval", "collisions_per_1000"} <= set(info)


def test_stepping_an_ended_episode_is_refused_until_reset():
    env = zumo_swarm.parallel_env(robots=2, pucks=10, max_steps=2)
    env.reset(seed=1)
    env.step({"robot_0": 1, "robot_1": 2})
    _, _, _, truncations, _ = env.step({"robot_0": 1, "robot_1": 2})
    assert all(truncations.values()) and env.agents == []
    with pytest.raises(RuntimeError, match="call reset"):
        env.step({"robot_0": 1, "robot_1": 2})
    env.reset()
    assert env.agents == ["robot_0", "robot_1"]


def test_a_missing_agent_action_is_named():
    env = zumo_swarm.parallel_env(robots=3, pucks=10)
    env.reset()
    with pytest.raises(ValueError, match="no action for robot_2"):
        env.step({"robot_0": 0, "robot_1": 0})


def test_an_action_for_an_agent_that_does_not_exist_is_refused():
    env = zumo_swarm.parallel_env(robots=2, pucks=10)
    env.reset()
    with pytest.raises(ValueError, match="no agent is named robot_7 .*robot_0 to robot_1"):
        env.step({"robot_0": 0, "robot_1": 0, "robot_7": 1})


def test_the_global_state_holds_every_body_and_the_field_under_it():
    env = zumo_swarm.parallel_env(robots=3, pucks=10, seed=2)
    env.reset()
    state = env.state()
    assert env.state_space.shape == (5 * 3 + 3 * 10,) and state.dtype == np.float32
    assert env.state_space.contains(state)
    positions, headings = env.positions()
    robots = state[:15].reshape(3, 5)
    pucks = state[15:].reshape(10, 3)
    # positions over the arena's side (the thesis' square: 800 units)
    assert np.allclose(robots[:, :2], positions[:3] / 800.0, atol=1e-6)
    assert np.allclose(pucks[:, :2], positions[3:] / 800.0, atol=1e-6)
    assert np.allclose(robots[:, 2], np.cos(headings), atol=1e-6)
    assert np.allclose(robots[:, 3], np.sin(headings), atol=1e-6)
    assert ((0 <= pucks[:, 2]) & (pucks[:, 2] <= 1)).all()
    env.step({agent: 1 for agent in env.agents})
    assert not np.array_equal(env.state(), state), "the state follows the world"
    assert "render_fps" in env.metadata


def test_render_returns_an_rgb_picture_of_the_world():
    env = zumo_swarm.parallel_env(render_mode="rgb_array", render_size=120)
    env.reset()
    frame = env.render()
    assert frame.shape == (120, 120, 3) and frame.dtype == np.uint8
    assert zumo_swarm.parallel_env().render() is None
