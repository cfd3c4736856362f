"""Tables learned in Python become policy blobs that `host policy
inspect` and `host flash` accept."""

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
    flash = run_host(host, "flash", "--policy", str(path), "--port", "/dev/ttyACM0", "--dry-run").stdout
    assert "avrdude" in flash and "bits7" in flash

    back = zumo_swarm.load_policy(path)
    assert np.array_equal(back.table, np.arange(128) % 3)
    assert (back.hasher, back.forward_speed, back.field) == ("bits7", 1.5, "annulus")
    assert np.array_equal(np.float32(back.actions), np.float32([0.3, 0.0, -0.3])), "the blob's f32 speeds"


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
