"""The PettingZoo parallel environment: one world, one agent per robot."""

from __future__ import annotations

from typing import Any

import numpy as np
from gymnasium import spaces
from pettingzoo import ParallelEnv

from zumo_swarm._settings import (
    ONE_WORLD_RENDER_MODES,
    OneWorld,
    check_render,
    check_seed,
    flat_actions,
    make_batch,
    robot_action_space,
    robot_observation_space,
    world_info,
)


class SwarmParallelEnv(OneWorld, ParallelEnv):
    """The swarm as a PettingZoo ``ParallelEnv``: agents ``robot_0`` ...
    ``robot_{n-1}``, each observing its own sensors and choosing its own
    action; every agent receives the same global reward (the thesis').

    An episode terminates when the shape forms (Eval above 0.94 at a
    check, every 100 steps) and is truncated at the stuck limit (150,000
    steps on the annulus, 50,000 on letters and images) or after
    ``max_steps``; then every agent leaves ``agents`` until ``reset()``.
    ``infos[agent]`` holds the world's ``eval``, ``episode_step``,
    ``robot_contacts`` (pairs touching this step) and the counters
    ``formations``, ``stuck_episodes``, ``total_steps``, ``mean_eval``,
    ``collisions_per_1000`` since the world was seeded.

    ``reset(seed=s)`` starts afresh from seed ``s`` (0 to 2**63 - 1; ``host
    run --seed s`` starts from the same world); ``reset()`` starts the next
    episode. ``step()`` before the first ``reset()``, or either after
    ``close()``, raises ``RuntimeError``.
    Keyword arguments: see :func:`zumo_swarm.parallel_env`.
    """

    metadata = {"name": "zumo_swarm_v0", "render_modes": ONE_WORLD_RENDER_MODES, "render_fps": 30, "is_parallelizable": True}

    def __init__(self, *, render_mode: str | None = None, render_size: int = 800, **settings: Any) -> None:
        self.render_mode, self.render_size = check_render(render_mode, render_size, ONE_WORLD_RENDER_MODES)
        self.settings = dict(settings)
        self._batch = make_batch(1, "off", 1, settings, ("render_mode", "render_size"))
        self.possible_agents = [f"robot_{i}" for i in range(self._batch.robots)]
        self.agents: list[str] = []
        self._observation_space = robot_observation_space(self._batch)
        self._action_space = robot_action_space(self._batch)
        #: The global state :meth:`state` returns.
        self.state_space = spaces.Box(-1.0, 1.0, shape=(self._batch.state_size,), dtype=np.float32)
        self._start_view()

    def observation_space(self, agent: str):
        """Every agent's observation space (the same object for all)."""
        return self._observation_space

    def action_space(self, agent: str):
        """Every agent's action space (the same object for all)."""
        return self._action_space

    def _observations(self, obs: np.ndarray) -> dict[str, Any]:
        return {agent: obs[i] for i, agent in enumerate(self.possible_agents)}

    def reset(self, seed: int | None = None, options: dict | None = None):
        self._check_open("reset")
        obs = self._batch.reset(None if seed is None else check_seed(seed))[0]
        self._was_reset()
        self.agents = list(self.possible_agents)
        return self._observations(obs), {agent: {} for agent in self.agents}

    def step(self, actions: dict[str, Any]):
        self._check_step()
        if not self.agents:
            raise RuntimeError("step() without live agents: the episode has ended: call reset()")
        missing = [agent for agent in self.possible_agents if agent not in actions]
        if missing:
            raise ValueError(f"actions: no action for {', '.join(missing)}")
        unknown = [str(agent) for agent in actions if agent not in self.possible_agents]
        if unknown:
            raise ValueError(f"actions: no agent is named {', '.join(unknown)} (the agents are robot_0 to robot_{len(self.possible_agents) - 1})")
        ordered = [np.asarray(actions[agent]).reshape(-1) for agent in self.possible_agents]
        if any(a.size != 1 for a in ordered):
            raise ValueError("actions: each agent's action must be one number (an action index or an angular speed)")
        stacked = np.concatenate(ordered).reshape(1, len(self.possible_agents))
        obs, _, terminated, truncated, info, robot_rewards = self._batch.step(
            flat_actions(self._batch, stacked, stacked.shape)
        )
        term, trunc = bool(terminated[0]), bool(truncated[0])
        scalars = world_info(info, 0)
        agents = self.agents
        if term or trunc:
            self.agents = []
        return (
            self._observations(obs[0]),
            {agent: float(r) for agent, r in zip(agents, robot_rewards[0])},
            {agent: term for agent in agents},
            {agent: trunc for agent in agents},
            {agent: dict(scalars) for agent in agents},
        )

    def state(self) -> np.ndarray:
        """The world's global state (``state_space``): per robot its position
        over the arena's size, its heading's cosine and sine and the field
        value under it; then per puck its position and the field value under
        it."""
        return self._batch.state(0)

