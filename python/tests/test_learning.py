"""A tabular Q-learner written in Python over the environment (the
example of docs/python-examples.md) forms an annulus within a step budget in which
random actions form none."""

import sys

import numpy as np

import zumo_swarm

BUDGET = 60_000
SEED = 1


def test_python_q_learning_forms_an_annulus_where_random_actions_form_none(repo):
    sys.path.insert(0, str(repo / "python" / "examples"))
    import tabular_q

    q, formations, _ = tabular_q.train(steps=BUDGET, seed=SEED)
    assert formations >= 1
    assert not np.all(q == 1.0), "the table learned"

    env = zumo_swarm.vector_env(1, observation="state", seed=SEED)
    env.reset(seed=SEED)
    rng = np.random.default_rng(SEED)
    for _ in range(BUDGET // 1000):
        for actions in rng.integers(0, 4, (1000, 1, 8)):
            _, _, terminated, _, info = env.step(actions)
            assert not terminated.any()
    assert info["formations"][0] == 0 and info["total_steps"][0] >= BUDGET - 1


def test_from_a_pessimistic_start_the_same_learner_forms_nothing(repo):
    sys.path.insert(0, str(repo / "python" / "examples"))
    import tabular_q

    q, formations, _ = tabular_q.train(steps=BUDGET, seed=SEED, initial_q=-10.0)
    assert formations == 0
    assert not np.all(q == -10.0), "the table was updated"
