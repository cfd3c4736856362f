"""The neural examples run end to end at a small step count: they train,
log episode returns and Eval, and their exported table round-trips
through a policy blob. Their learning figures are a benchmark's
(python/benchmarks/learning.py), not a test's. PyTorch and
Stable-Baselines3 are large and not in the test environment
(python/requirements-test.txt): without them these tests skip."""

import sys

import numpy as np
import pytest

import zumo_swarm


@pytest.fixture(autouse=True)
def examples_on_path(repo):
    sys.path.insert(0, str(repo / "python" / "examples"))
    yield
    sys.path.remove(str(repo / "python" / "examples"))


def test_the_shared_policy_ppo_example_trains_logs_and_exports_its_table(tmp_path):
    torch = pytest.importorskip("torch")
    import marl_ppo

    args = marl_ppo.parse(["--steps", "2048", "--worlds", "4", "--rollout", "64", "--max-steps", "100", "--reward", "per-robot"])
    agent, env, log = marl_ppo.train(args)
    assert len(log["episodes"]) >= 4, "ended episodes' returns are logged"
    assert all(0.0 < e <= 1.0 for _, e in log["episodes"])
    assert env.episode_count >= 16 and len(env.return_queue) > 0
    table = agent.table()
    assert table.shape == (256,) and set(table) <= {0, 1, 2, 3}
    path = zumo_swarm.export_policy(tmp_path / "marl.policy", table, env=env, trainer_steps=2048)
    policy = zumo_swarm.load_policy(path)
    assert np.array_equal(policy.table, table)
    assert policy.trained_for == ("disc", "thesis") and policy.hasher == "original"
    states = np.arange(256).reshape(32, 8)
    with torch.no_grad():
        greedy = agent(torch.as_tensor(states))[0].argmax(-1).numpy()
    assert np.array_equal(policy.act(states), greedy), "the blob acts as the network does greedily"


def test_the_shared_q_network_example_trains_logs_and_exports_its_table(tmp_path):
    pytest.importorskip("torch")
    import marl_q

    args = marl_q.parse(["--steps", "2048", "--worlds", "4", "--max-steps", "100", "--select-every", "1024", "--select-steps", "200"])
    q, env, log = marl_q.train(args)
    assert log["selected_step"] in (1024, 2048) and log["selected_formations"] >= 0, "two evaluations, the best kept"
    if log["selected_step"] == 2048:
        assert np.array_equal(log["selected"], q.values())
    assert len(log["episodes"]) >= 4, "ended episodes' returns are logged"
    assert all(0.0 < e <= 1.0 for _, e in log["episodes"])
    weights = q.linear.weight.detach()
    assert (weights != args.initial_q).any(), "the steps moved some Q-values"
    values = log["selected"]
    assert values.shape == (256, 4)
    path = zumo_swarm.export_policy(tmp_path / "marl-q.policy", values, env=env, trainer_steps=2048)
    policy = zumo_swarm.load_policy(path)
    best = values == values.max(axis=1, keepdims=True)
    masks = (best * (1 << np.arange(4))).sum(axis=1)
    assert np.array_equal(policy.sets, masks), "the blob keeps every best action of the network's table"
    assert (best.sum(axis=1) > 1).any(), "states never met keep their four tied actions"


def test_the_sb3_ppo_example_logs_returns_and_eval_and_exports_its_table(tmp_path):
    pytest.importorskip("stable_baselines3")
    import ppo_sb3

    model, env, selected = ppo_sb3.train(steps=1024, worlds=4, max_steps=100, select_steps=100)
    episodes = list(model.ep_info_buffer)
    assert len(episodes) >= 4 and all("r" in e and 0.0 < e["eval"] <= 1.0 for e in episodes)
    assert model.policy.noise is not None, "the worlds explored on their own draws"
    table = model.policy.table()
    assert table.shape == (256,)
    robots = env.venv.venv.batch.robots
    for mixed in np.random.default_rng(1).integers(0, 256, (5, robots)):
        acted, _ = model.predict(mixed[None, :], deterministic=True)
        assert np.array_equal(acted[0], table[mixed]), "each robot acts as the table says for its own state"
    assert np.array_equal(selected, table), "with one check, at the end, the last table is the selected one"
    path = zumo_swarm.export_policy(tmp_path / "ppo.policy", table, env=env.venv.venv, trainer_steps=1024)
    assert np.array_equal(zumo_swarm.load_policy(path).table, table)
