"""A Stable-Baselines3 ``VecEnv`` over :class:`zumo_swarm.SwarmVectorEnv`:
one SB3 environment per world (the single-agent view: every robot's
observation stacked, ``MultiDiscrete`` actions, the global reward), the
worlds stepped in Rust threads. Needs ``stable-baselines3`` (not a
dependency of this package)::

    import torch
    from stable_baselines3 import PPO
    from zumo_swarm.sb3 import SB3VecEnv

    torch.set_num_threads(1)  # the worlds' threads have the cores
    env = SB3VecEnv(16, max_steps=2_000)
    PPO("MlpPolicy", env).learn(1_000_000)

``torch.set_num_threads(1)`` first: PyTorch's default, a thread per core,
contends with the worlds' threads for every core, and a small network
gains nothing from them (without it this example ran 13 times slower on
2 cores, docs/python-examples.md).

SB3 resets an environment in the step that ends its episode and puts the
last observation in ``infos[i]["terminal_observation"]``: the adapter runs
the worlds with same-step autoreset, which does exactly that, and marks
truncations with ``infos[i]["TimeLimit.truncated"]``.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from stable_baselines3.common.vec_env.base_vec_env import VecEnv

from zumo_swarm.vector import SwarmVectorEnv


class SB3VecEnv(VecEnv):
    """``num_worlds`` worlds as an SB3 ``VecEnv``; keyword arguments as
    :func:`zumo_swarm.vector_env`'s (``autoreset_mode`` is the adapter's).
    ``formations``: the shapes every world formed since it was built."""

    def __init__(self, num_worlds: int, **settings: Any) -> None:
        self.venv = SwarmVectorEnv(num_worlds, autoreset_mode="same-step", **settings)
        self.render_mode = self.venv.render_mode
        super().__init__(num_worlds, self.venv.single_observation_space, self.venv.single_action_space)
        self._actions: np.ndarray | None = None
        self.formations = 0

    def reset(self) -> np.ndarray:
        seeds = None if all(s is None for s in self._seeds) else [0 if s is None else s for s in self._seeds]
        obs, _ = self.venv.reset(seed=seeds)
        self._reset_seeds()
        return obs

    def step_async(self, actions: np.ndarray) -> None:
        self._actions = np.asarray(actions)

    def step_wait(self):
        obs, _, terminated, truncated, info = self.venv.step(self._actions)
        dones = terminated | truncated
        self.formations = int(info["formations"].sum())
        infos: list[dict[str, Any]] = [{} for _ in range(self.num_envs)]
        for i in np.flatnonzero(dones):
            infos[i]["terminal_observation"] = info["final_obs"][i]
            infos[i]["TimeLimit.truncated"] = bool(truncated[i] and not terminated[i])
        for i, world in enumerate(infos):
            world["eval"] = float(info["eval"][i])
        return obs, info["world_reward"].astype(np.float32), dones, infos

    def close(self) -> None:
        self.venv.close()

    def get_images(self) -> list[np.ndarray]:
        return list(self.venv.render() or ())

    def get_attr(self, attr_name: str, indices=None) -> list[Any]:
        return [getattr(self.venv, attr_name)] * len(self._get_indices(indices))

    def set_attr(self, attr_name: str, value: Any, indices=None) -> None:
        setattr(self.venv, attr_name, value)

    def env_method(self, method_name: str, *method_args, indices=None, **method_kwargs) -> list[Any]:
        result = getattr(self.venv, method_name)(*method_args, **method_kwargs)
        return [result] * len(self._get_indices(indices))

    def env_is_wrapped(self, wrapper_class, indices=None) -> list[bool]:
        return [False] * len(self._get_indices(indices))
