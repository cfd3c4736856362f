"""The neural examples run end to end at a small step count: they train,
log episode returns and Eval, and their exported table round-trips
through a policy blob; run as scripts they log as CleanRL does and end
with a summary holding the held-out evaluation. Their learning figures
are a benchmark's (python/benchmarks/learning.py), not a test's. PyTorch
and Stable-Baselines3 are large and not in the test environment
(python/requirements-test.txt): without them those tests skip; the run
log and the held-out evaluation they share (run_log.py) need neither and
are tested here always."""

import csv
import importlib.util
import json
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


def scalars(run_dir):
    """The rows of a run's scalars.csv."""
    with open(run_dir / "scalars.csv", newline="") as f:
        return list(csv.DictReader(f))


def test_the_run_log_writes_csv_always_and_says_when_tensorboard_is_missing(tmp_path, capsys, monkeypatch):
    import run_log

    monkeypatch.setattr(run_log, "tensorboard_writer", lambda directory: None)
    log = run_log.RunLog("example", {"seed": 3, "lr": 0.1}, str(tmp_path / "run"))
    log.scalar("charts/episodic_return", -12.5, 640)
    log.scalar("charts/SPS", 1000, 1280)
    first = scalars(tmp_path / "run")[0]
    assert (first["global_step"], first["tag"], first["value"]) == ("640", "charts/episodic_return", "-12.5")
    log.finish({"held-out evaluation": "3 formations"})
    out = capsys.readouterr().out
    assert "TensorBoard is not installed: logging to" in out
    assert "summary of example:\n  held-out evaluation: 3 formations\n  log: " in out
    assert [r["tag"] for r in scalars(tmp_path / "run")] == ["charts/episodic_return", "charts/SPS"]
    assert json.loads((tmp_path / "run" / "config.json").read_text()) == {"seed": 3, "lr": 0.1}
    assert json.loads((tmp_path / "run" / "summary.json").read_text())["held-out evaluation"] == "3 formations"


def test_the_run_log_writes_tensorboard_events_beside_the_csv_when_tensorboard_is_installed(tmp_path, capsys):
    pytest.importorskip("tensorboard")
    pytest.importorskip("torch")
    import run_log

    log = run_log.RunLog("example", {"seed": 1}, str(tmp_path / "run"))
    log.scalar("charts/episodic_return", 1.0, 1)
    log.finish({})
    assert list((tmp_path / "run").glob("events.out.tfevents.*")), "TensorBoard's event file"
    assert "TensorBoard is not installed" not in capsys.readouterr().out


def test_the_held_out_evaluation_runs_a_table_on_the_evaluation_seeds_and_logs_it(tmp_path, monkeypatch):
    import run_log

    monkeypatch.setattr(run_log, "tensorboard_writer", lambda directory: None)
    assert run_log.EVAL_SEEDS == list(range(1001, 1011))
    still = run_log.evaluate(lambda states: np.zeros_like(states), 300, forward_speed=0.0)
    env = zumo_swarm.vector_env(10, observation="state", forward_speed=0.0)
    env.reset(seed=run_log.EVAL_SEEDS)
    assert still["final_eval"] == pytest.approx(env.step(np.zeros((10, 8), dtype=np.int64))[4]["eval"].mean())
    assert still["formations"] == 0
    log = run_log.RunLog("example", {}, str(tmp_path / "run"))
    line = run_log.held_out(lambda states: states % 4, 200, log, 5000)
    assert line.endswith("(greedy table, seeds 1001 to 1010, 200 steps each)")
    assert {r["tag"] for r in scalars(tmp_path / "run")} == {"eval/formations", "eval/final_eval", "eval/mean_eval"}
    assert {r["global_step"] for r in scalars(tmp_path / "run")} == {"5000"}


@pytest.mark.parametrize("example", ["marl_ppo", "marl_q"])
def test_each_multi_agent_example_prints_every_update_logs_and_ends_with_the_held_out_evaluation(
        example, tmp_path, capsys):
    pytest.importorskip("torch")
    module = __import__(example)
    args = ["--steps", "2048", "--worlds", "4", "--max-steps", "100", "--eval-steps", "100",
            "--out", str(tmp_path / "p.policy"), "--run-dir", str(tmp_path / "run")]
    if example == "marl_ppo":
        args += ["--rollout", "64"]
    else:
        args += ["--select-every", "1024", "--select-steps", "100"]
    summary = module.main(args)
    out = capsys.readouterr().out
    if example == "marl_ppo":
        assert [line.split(",")[0] for line in out.splitlines() if line.startswith("update ")] == \
            [f"update {u}/8" for u in range(1, 9)], "a line every update, episodes ended or not"
    assert summary["held-out evaluation"].endswith("(greedy table, seeds 1001 to 1010, 100 steps each)")
    assert f"summary of {example}:" in out and "held-out evaluation: " in out
    tags = {r["tag"] for r in scalars(tmp_path / "run")}
    assert {"charts/episodic_return", "charts/episodic_length", "charts/episodic_eval",
            "eval/formations", "eval/final_eval"} <= tags
    assert zumo_swarm.load_policy(tmp_path / "p.policy").table.shape == (256,)


def test_the_sb3_example_logs_episodes_and_evaluations_and_ends_with_the_held_out_evaluation(tmp_path, capsys):
    pytest.importorskip("stable_baselines3")
    import ppo_sb3

    summary = ppo_sb3.main(["2048", "--eval-steps", "100", "--out", str(tmp_path / "p.policy"),
                            "--run-dir", str(tmp_path / "run")])
    assert summary["held-out evaluation"].endswith("(greedy table, seeds 1001 to 1010, 100 steps each)")
    assert "summary of ppo_sb3:" in capsys.readouterr().out
    tags = {r["tag"] for r in scalars(tmp_path / "run")}
    assert {"eval/selection_formations", "eval/formations"} <= tags


def test_the_sb3_adapters_example_sets_torchs_threads_before_it_trains():
    source = open(importlib.util.find_spec("zumo_swarm").submodule_search_locations[0] + "/sb3.py").read()
    example = source[source.index("::\n"):source.index("learn(1_000_000)")]
    assert "torch.set_num_threads(1)" in example, "without it PyTorch's threads contend with the worlds'"
    assert example.index("torch.set_num_threads(1)") < example.index("PPO(")
