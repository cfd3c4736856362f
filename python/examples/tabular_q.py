"""Tabular Q-learning over the simulator, one table shared by all robots (the thesis' learner)."""
import numpy as np
import zumo_swarm


def train(steps=200_000, seed=1, alpha=0.2, gamma=0.9, reward="reference", initial_q=1.0, epsilon=0.0):
    """Greedy Q-learning from `initial_q` (1.0: above what the reference
    reward pays, so untried actions look best, the thesis' exploration);
    `epsilon` > 0 replaces that share of the robots' actions by random ones."""
    env = zumo_swarm.gym_env(observation="state", hasher="original", seed=seed, reward=reward, gamma=gamma)
    q = np.full((env.batch.num_states, len(env.batch.angular_speeds)), initial_q)
    rng = np.random.default_rng(seed)
    states, _ = env.reset(seed=seed)
    formations = 0
    for _ in range(steps):
        rows = q[states]  # greedy, ties broken at random
        actions = np.where(rows == rows.max(axis=1, keepdims=True), rng.random(rows.shape), -1).argmax(axis=1)
        if epsilon > 0:
            actions = np.where(rng.random(len(actions)) < epsilon, rng.integers(0, rows.shape[1], len(actions)), actions)
        next_states, reward, terminated, truncated, info = env.step(actions)
        for s, a, s2 in zip(states, actions, next_states):  # robot by robot, each update seeing the last
            q[s, a] += alpha * (reward + gamma * q[s2].max() - q[s, a])
        states = next_states
        if terminated or truncated:
            formations += terminated
            states, _ = env.reset()
    return q, formations, env


if __name__ == "__main__":
    q, formations, env = train()
    print(f"{formations} annuli formed")
    zumo_swarm.export_policy("out/python-annulus.policy", q, env=env, trainer_steps=200_000, seed=1)
