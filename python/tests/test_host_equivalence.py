"""The same seed and settings give the same run as `host`: a shipped
policy's greedy actions, computed in Python from the hashed-state
observation, reproduce `host run --controller policy:FILE` and the picture
`host render` draws after the same steps."""

import json

import numpy as np
import pytest
from PIL import Image

import zumo_swarm
from conftest import run_host

CASES = [
    ("policies/oc-heuristic.policy", "disc", 7, 40_000),  # 9 formations: resets included
    ("policies/robot-annulus-8bit.policy", "robot", 3, 4_000),
    ("policies/robot-annulus-10bit.policy", "robot", 5, 3_000),
]


@pytest.mark.parametrize("policy_file, sensors, seed, steps", CASES, ids=[c[0].split("/")[1] for c in CASES])
def test_greedy_actions_from_python_reproduce_host_run_and_host_render(host, repo, tmp_path, policy_file, sensors, seed, steps):
    policy = zumo_swarm.load_policy(repo / policy_file)
    env = zumo_swarm.gym_env(
        observation="state",
        hasher=policy.hasher,
        actions=policy.actions,
        forward_speed=policy.forward_speed,
        sensors=sensors,
        seed=seed,
        render_mode="rgb_array",
        render_size=240,
    )
    states, _ = env.reset(seed=seed)
    info = {"total_steps": 0}
    while info["total_steps"] < steps:
        states, _, terminated, truncated, info = env.step(policy.act(states))
        if terminated or truncated:
            states, _ = env.reset()

    common = ["--controller", f"policy:{repo / policy_file}", "--sensors", sensors, "--seed", str(seed), "--steps", str(steps)]
    summary = json.loads(run_host(host, "run", *common, "--json").stdout)
    ours = {k: info[k] for k in ("formations", "collisions_per_1000", "mean_eval")}
    ours["stuck"] = info["stuck_episodes"]
    ours["steps"] = info["total_steps"]
    assert ours == {k: summary[k] for k in ours}, "the Eval trace (mean over every check) and counters agree exactly"
    if sensors == "disc":
        assert summary["formations"] >= 1, "the run covers episode resets"

    png = tmp_path / "host.png"
    run_host(host, "render", *common, "--size", "240", "--out", str(png))
    assert np.array_equal(env.render(), np.asarray(Image.open(png).convert("RGB"))), "every body is where host put it"
