"""Tables learned in Python become policy blobs that `host policy
inspect` and `host flash` accept."""

import subprocess

import numpy as np
import pytest

import zumo_swarm
from conftest import run_host


def test_an_exported_q_table_is_inspected_and_accepted_for_flashing_by_host(host, repo, tmp_path):
    env = zumo_swarm.gym_env(observation="state", hasher="bits7", actions=[0.3, 0.0, -0.3], forward_speed=1.5)
    q = np.zeros((128, 3))
    q[np.arange(128), np.arange(128) % 3] = 1.0
    path = zumo_swarm.export_policy(tmp_path / "python.policy", q, env=env, trainer_steps=1234, seed=5)

    inspect = run_host(host, "policy", "inspect", str(path)).stdout
    assert "hasher     bits7 (7 bits) (128 states)" in inspect
    assert "actions    [0.3, 0.0, -0.3] rad/step, forward 1.5 units/step" in inspect
    assert "trained    1234 steps, seed 5" in inspect
    assert "name       python" in inspect
    assert "for        sensors disc, arena thesis" in inspect
    # a table for the disc sensors is refused for a robot unless asked for
    refused = subprocess.run(
        [str(host), "flash", "--policy", str(path), "--port", "/dev/ttyACM0", "--dry-run"],
        cwd=repo, capture_output=True, text=True,
    )
    assert refused.returncode != 0 and "--any-sensors" in refused.stderr
    flash = run_host(host, "flash", "--policy", str(path), "--port", "/dev/ttyACM0", "--dry-run", "--any-sensors").stdout
    assert "avrdude" in flash and "bits7" in flash

    back = zumo_swarm.load_policy(path)
    assert np.array_equal(back.table, np.arange(128) % 3)
    assert (back.hasher, back.forward_speed, back.field) == ("bits7", 1.5, "annulus")
    assert np.array_equal(np.float32(back.actions), np.float32([0.3, 0.0, -0.3])), "the blob's f32 speeds"


def test_a_q_table_with_equal_best_actions_keeps_them_all_for_the_robot(host, tmp_path):
    env = zumo_swarm.gym_env(observation="state", sensors="robot")
    q = np.zeros((256, 4))
    q[:, 1] = 1.0  # one best action ...
    q[7, 3] = 1.0  # ... except state 7: actions 1 and 3
    q[9] = 2.0  # and state 9: all four
    path = zumo_swarm.export_policy(tmp_path / "ties.policy", q, env=env)
    back = zumo_swarm.load_policy(path)
    assert back.version == 2 and back.trained_for == ("robot", "tv75")
    assert back.sets[7] == 0b1010 and back.sets[9] == 0b1111 and back.sets[0] == 0b0010
    assert back.table[7] == 1 and back.table[9] == 0, "the table holds each set's lowest action"
    inspect = run_host(host, "policy", "inspect", str(path)).stdout
    assert "ties       1 states with 2 best actions, 0 with 3, 1 with 4" in inspect
    # without ties or an environment: format version 1, as before
    plain = zumo_swarm.load_policy(zumo_swarm.export_policy(tmp_path / "plain.policy", np.eye(4)[np.arange(256) % 4]))
    assert plain.version == 1 and plain.trained_for is None


def test_a_shipped_blob_round_trips_through_load_and_export(repo, tmp_path):
    shipped = repo / "policies" / "oc-heuristic.policy"
    policy = zumo_swarm.load_policy(shipped)
    again = zumo_swarm.export_policy(
        tmp_path / "copy.policy", policy.table, hasher=policy.hasher, actions=policy.actions,
        forward_speed=policy.forward_speed, field=policy.field, name=policy.name,
        trainer_steps=policy.trainer_steps, seed=policy.seed,
    )
    assert again.read_bytes() == shipped.read_bytes()


@pytest.mark.parametrize(
    "table, error, message",
    [
        (np.zeros(10, dtype=np.int64), ValueError, r"table = <10 entries>: hasher original has 256 states"),
        (np.full(256, 7), ValueError, r"table\[0\] = 7: must be an action index in 0..4"),
        (np.zeros(256), TypeError, r"table: a greedy table holds action indices"),
        (np.full((256, 4), np.nan), ValueError, r"table: a Q-table .* finite numbers"),
        (np.zeros((2, 2, 2)), ValueError, r"table: expected a Q-table"),
    ],
)
def test_a_bad_table_is_refused_and_no_file_is_written(tmp_path, table, error, message):
    target = tmp_path / "bad.policy"
    with pytest.raises(error, match=message):
        zumo_swarm.export_policy(target, table)
    assert list(tmp_path.iterdir()) == []


def test_a_file_that_is_not_a_policy_is_named(tmp_path):
    bad = tmp_path / "notes.policy"
    bad.write_bytes(b"hello")
    with pytest.raises(ValueError, match="notes.policy"):
        zumo_swarm.load_policy(bad)
