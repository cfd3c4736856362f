"""``render_mode="human"``: the environments of one world serve the live
view of their own world (docs/view.md) on loopback, show every step and
reset, and stop serving when closed."""

import json
import time
import urllib.error
import urllib.request

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env
from pettingzoo.test import render_test
from pettingzoo.utils.conversions import parallel_to_aec

import zumo_swarm

SMALL = {"robots": 3, "pucks": 10}


def served_frame(url):
    """The frame the view serves now (``GET /state.json``)."""
    with urllib.request.urlopen(url + "state.json", timeout=10) as reply:
        return json.load(reply)["frame"]


def frame_at(url, step):
    """Waits (at most 10 s: the view's thread sends the newest frame within
    a 60th of a second) until the served frame is at ``step``."""
    deadline = time.monotonic() + 10
    while True:
        frame = served_frame(url)
        if frame["step"] == step or time.monotonic() > deadline:
            return frame
        time.sleep(0.02)


def robots_xy(frame):
    return np.array(frame["robots"], dtype=np.float32).reshape(-1, 4)[:, :2]


def test_gymnasiums_environment_checker_passes_in_human_mode():
    env = gym.make("zumo_swarm/Swarm-v0", render_mode="human", **SMALL)
    check_env(env.unwrapped, skip_render_check=False)
    assert env.unwrapped.metadata["render_fps"] == 30
    env.close()


def test_pettingzoos_render_test_passes_in_every_mode():
    render_test(lambda render_mode=None: parallel_to_aec(zumo_swarm.parallel_env(render_mode=render_mode, **SMALL)))


def test_the_gymnasium_env_serves_each_step_of_its_own_world_and_closing_stops_it(capsys):
    env = zumo_swarm.gym_env(render_mode="human", **SMALL)
    url = env.view_url
    assert url.startswith("http://127.0.0.1:") and url.endswith("/")
    assert capsys.readouterr().out.count(url) == 1, "the address is printed once"
    env.reset(seed=3)
    assert frame_at(url, 0)["step"] == 0
    for _ in range(5):
        env.step(env.action_space.sample())
    frame = frame_at(url, 5)
    assert frame["step"] == 5
    positions = np.asarray(env.positions()[0])[: SMALL["robots"]]
    np.testing.assert_allclose(robots_xy(frame), positions, rtol=1e-6)
    assert env.render() is None
    # a new episode: the view starts again from its first step
    env.reset()
    assert frame_at(url, 5)["episode_step"] == 0
    env.close()
    with pytest.raises(urllib.error.URLError):
        served_frame(url)


def test_the_parallel_env_serves_each_step_and_refuses_the_pages_controls():
    env = zumo_swarm.parallel_env(render_mode="human", **SMALL)
    url = env.view_url
    env.reset(seed=4)
    for _ in range(7):
        env.step({agent: env.action_space(agent).sample() for agent in env.agents})
    assert frame_at(url, 7)["step"] == 7
    request = urllib.request.Request(url + "control?action=play", method="POST")
    with pytest.raises(urllib.error.HTTPError) as refused:
        urllib.request.urlopen(request, timeout=10)
    assert refused.value.code == 400
    assert "follows a world its owner steps" in refused.value.read().decode()
    assert served_frame(url)["step"] == 7
    env.close()
    with pytest.raises(urllib.error.URLError):
        served_frame(url)


def test_the_vector_env_has_no_human_mode():
    with pytest.raises(ValueError, match=r"render_mode = 'human': expected None or 'rgb_array'$"):
        zumo_swarm.vector_env(2, render_mode="human", **SMALL)
