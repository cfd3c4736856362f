"""The single-agent Gymnasium view of one world: one shared policy acts
for every robot, as in the thesis."""

from __future__ import annotations

from typing import Any

import gymnasium as gym

from zumo_swarm._settings import (
    ONE_WORLD_RENDER_MODES,
    OneWorld,
    check_render,
    check_seed,
    flat_actions,
    make_batch,
    world_action_space,
    world_info,
    world_observation_space,
)


class SwarmEnv(OneWorld, gym.Env):
    """One world as a Gymnasium ``Env``: the observation stacks every
    robot's (``(robots, 7)`` floats, or ``robots`` hashed states), the
    action is ``MultiDiscrete`` over the robots (or angular speeds), the
    reward is the global reward. ``terminated`` on a formation,
    ``truncated`` at the stuck limit or ``max_steps``; ``info`` as in
    :class:`zumo_swarm.parallel.SwarmParallelEnv`.

    ``reset(seed=s)`` starts afresh from seed ``s`` (0 to 2**63 - 1), the
    world ``host run --seed s`` starts from; ``reset()`` starts the next
    episode (the very first one is the constructor's ``seed``'s). ``step()``
    before the first ``reset()``, or either after ``close()``, raises
    ``RuntimeError``.
    """

    metadata = {"render_modes": ONE_WORLD_RENDER_MODES, "render_fps": 30}

    def __init__(self, *, render_mode: str | None = None, render_size: int = 800, **settings: Any) -> None:
        self.render_mode, self.render_size = check_render(render_mode, render_size, ONE_WORLD_RENDER_MODES)
        self.settings = dict(settings)
        self._batch = make_batch(1, "off", 1, settings, ("render_mode", "render_size"))
        self.observation_space = world_observation_space(self._batch)
        self.action_space = world_action_space(self._batch)
        self._start_view()

    @property
    def batch(self):
        """The native batch of one world (action table, hasher, limits)."""
        return self._batch

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        self._check_open("reset")
        if seed is not None:
            seed = check_seed(seed)
        super().reset(seed=seed)
        obs = self._batch.reset(seed)
        self._was_reset()
        return obs[0], {}

    def step(self, action):
        self._check_step()
        flat = flat_actions(self._batch, action, self.action_space.shape)
        obs, rewards, terminated, truncated, info, _ = self._batch.step(flat)
        return obs[0], float(rewards[0]), bool(terminated[0]), bool(truncated[0]), world_info(info, 0)

