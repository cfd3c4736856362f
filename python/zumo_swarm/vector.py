"""Many worlds stepped in Rust threads: a Gymnasium vector environment with
per-robot arrays, and its single-agent view."""

from __future__ import annotations

import sys
from typing import Any, Sequence

import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv, VectorWrapper
from gymnasium.vector.utils import batch_space
from gymnasium.wrappers.vector import NormalizeReward, RecordEpisodeStatistics

from zumo_swarm._settings import (
    Lifecycle,
    check_render,
    check_seed,
    flat_actions,
    make_batch,
    world_action_space,
    world_observation_space,
)

_AUTORESET = {AutoresetMode.NEXT_STEP: "next-step", AutoresetMode.SAME_STEP: "same-step"}

#: Gymnasium's vector wrappers that keep one reward per world, which the
#: per-robot rewards ``(worlds, robots)`` break: with them NumPy fails to
#: broadcast, or, with as many robots as worlds, adds the wrong numbers.
WORLD_REWARD_WRAPPERS = (RecordEpisodeStatistics, NormalizeReward)


#: The methods through which those wrappers call the env's ``reset`` and
#: ``step``: only a call from one of them needs a look at who called.
_WRAPPER_CALLS = {
    method.__code__
    for wrapper in (VectorWrapper, *WORLD_REWARD_WRAPPERS)
    for method in (wrapper.reset, wrapper.step)
}


def refuse_world_reward_wrapper() -> None:
    """Raises ``TypeError`` when the caller of the :class:`SwarmVectorEnv`
    method that calls this is one of :data:`WORLD_REWARD_WRAPPERS`, saying
    what does work instead."""
    frame = sys._getframe(2)
    if frame.f_code not in _WRAPPER_CALLS:
        return
    caller = frame.f_locals.get("self")
    if isinstance(caller, WORLD_REWARD_WRAPPERS):
        wrapper = type(caller).__name__
        raise TypeError(
            f"gymnasium.wrappers.vector.{wrapper} cannot wrap zumo_swarm.vector_env: its rewards are per robot, "
            f"shape (worlds, robots), and {wrapper} keeps one reward per world. Wrap env.single_agent_view() "
            "(rewards (worlds,), the world's reward) instead"
            + (", or use zumo_swarm.RecordRobotEpisodeStatistics(env)" if wrapper == "RecordEpisodeStatistics" else "")
        )


class SwarmVectorEnv(Lifecycle, VectorEnv):
    """``num_worlds`` worlds of one configuration, stepped together in Rust
    threads (``threads``, default one per core) with no Python per robot or
    per world: NumPy arrays in, NumPy arrays out.

    - ``step(actions)``: ``actions`` of shape ``(worlds, robots)`` (action
      indices, or angular speeds with ``action="continuous"``); returns
      observations ``(worlds, robots, 7)`` float32 (or ``(worlds, robots)``
      hashed states), rewards ``(worlds, robots)`` float64 (every robot of
      a world the same global reward, except with ``reward="per-robot"``),
      terminations and truncations
      ``(worlds,)``, and ``infos``, a dict of ``(worlds,)`` arrays
      (``world_reward``: the world's reward, which the single-agent view
      returns; ``eval``,
      ``episode_step``, ``robot_contacts``, ``formations``,
      ``stuck_episodes``, ``total_steps``, ``mean_eval``,
      ``collisions_per_1000``, ``reset``), each with its ``_key`` mask.
    - Autoreset: Gymnasium's default, **next-step**
      (``AutoresetMode.NEXT_STEP``): the step in which a world's episode
      terminates or is truncated returns its last observation; the world's
      next step resets it, ignores its actions and returns the new
      episode's first observation with reward 0, not terminated nor
      truncated (``infos["reset"]`` marks it). ``autoreset_mode=
      AutoresetMode.SAME_STEP`` (or ``"same-step"``) resets in the ending
      step instead and puts the last observation in ``infos["final_obs"]``
      (rows of the worlds marked in ``infos["_final_obs"]``).
    - ``reset(seed=s)`` starts world ``i`` afresh from seed ``s + i`` (a list
      gives each world's seed; every seed from 0 to 2**63 - 1); ``reset()``
      starts every world's next episode. Before any reset, world ``i``
      holds seed ``seed + i``. ``step()`` before the first ``reset()``, or
      either after ``close()``, raises ``RuntimeError``.

    :meth:`single_agent_view` gives the Gymnasium-convention view: one
    environment per world, rewards of shape ``(worlds,)``. Gymnasium's
    wrappers that keep one reward per world (:data:`WORLD_REWARD_WRAPPERS`:
    ``RecordEpisodeStatistics``, ``NormalizeReward``) expect that shape:
    put directly on this per-robot env they are refused with a
    ``TypeError`` at their first reset or step; use
    :class:`RecordRobotEpisodeStatistics`, or wrap the single-agent view.
    Keyword arguments: see :func:`zumo_swarm.vector_env`.
    """

    def __init__(
        self,
        num_worlds: int,
        *,
        autoreset_mode: AutoresetMode | str = AutoresetMode.NEXT_STEP,
        threads: int | None = None,
        render_mode: str | None = None,
        render_size: int = 800,
        **settings: Any,
    ) -> None:
        mode = {name: m for m, name in _AUTORESET.items()}.get(autoreset_mode, autoreset_mode)
        if mode not in _AUTORESET:
            raise ValueError(f"autoreset_mode = {autoreset_mode!r}: expected 'next-step' or 'same-step'")
        self.render_mode, self.render_size = check_render(render_mode, render_size)
        self.settings = dict(settings)
        self._batch = make_batch(
            num_worlds, _AUTORESET[mode], threads, settings, ("autoreset_mode", "threads", "render_mode", "render_size")
        )
        self.num_envs = self._batch.num_worlds
        self.metadata = {"render_modes": ["rgb_array"], "autoreset_mode": mode}
        self.single_observation_space = world_observation_space(self._batch)
        self.single_action_space = world_action_space(self._batch)
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        self._action_shape = (self.num_envs, self._batch.robots)
        # Every info entry is for every world: one read-only mask for all.
        self._every_world = np.ones(self.num_envs, dtype=bool)
        self._every_world.flags.writeable = False

    @property
    def batch(self):
        """The native batch (action table, hasher, limits, threads)."""
        return self._batch

    def reset(self, *, seed: int | Sequence[int] | None = None, options: dict | None = None):
        self._check_open("reset")
        refuse_world_reward_wrapper()
        if seed is None:
            seeds = None
        elif isinstance(seed, (int, np.integer)):
            seeds = check_seed(seed)  # the native batch checks every world's, seeds + i
        else:
            seeds = [check_seed(s) for s in seed]
            if len(seeds) != self.num_envs:
                raise ValueError(f"seed: got {len(seeds)} seeds for {self.num_envs} worlds")
        obs = self._batch.reset(seeds)
        if seeds is not None:
            super().reset(seed=seeds if isinstance(seeds, int) else seeds[0])
        self._was_reset()
        return obs, {}

    def step(self, actions):
        self._check_step()
        refuse_world_reward_wrapper()
        flat = flat_actions(self._batch, actions, self._action_shape)
        obs, world_rewards, terminated, truncated, info, robot_rewards = self._batch.step(flat)
        info["world_reward"] = world_rewards
        for key in [k for k in info if not k.startswith("_") and k != "final_obs"]:
            info["_" + key] = self._every_world
        return obs, robot_rewards, terminated, truncated, info

    def close_extras(self, **kwargs: Any) -> None:
        """Marks the environment closed (``VectorEnv.close`` calls this once)."""
        self._closed = True

    def render(self):
        """Every world as ``host render`` draws it (``render_mode="rgb_array"``)."""
        if self.render_mode is None:
            return None
        return tuple(self._batch.render(i, self.render_size) for i in range(self.num_envs))

    def single_agent_view(self) -> SingleAgentVectorEnv:
        """This environment with Gymnasium's shapes: rewards ``(worlds,)``."""
        return SingleAgentVectorEnv(self)


class SingleAgentVectorEnv(VectorWrapper):
    """A :class:`SwarmVectorEnv` as one Gymnasium environment per world:
    observations and actions stack every robot's (``single_observation_space``
    and ``single_action_space`` are :class:`zumo_swarm.single.SwarmEnv`'s),
    the reward is the world's reward (``infos["world_reward"]``), shape
    ``(worlds,)``."""

    def step(self, actions):
        obs, _, terminated, truncated, info = self.env.step(actions)
        return obs, info["world_reward"].copy(), terminated, truncated, info


class _WorldReward(VectorWrapper):
    """Rewards of shape ``(worlds,)``, each world's mean over its robots;
    the robots' own in ``infos["robot_rewards"]``."""

    def step(self, actions):
        obs, rewards, terminated, truncated, info = self.env.step(actions)
        info["robot_rewards"] = rewards
        return obs, rewards.mean(axis=1), terminated, truncated, info


class RecordRobotEpisodeStatistics(VectorWrapper):
    """Gymnasium's ``RecordEpisodeStatistics`` for the per-robot
    :class:`SwarmVectorEnv`: the wrapped env's steps are unchanged (rewards
    ``(worlds, robots)``), and a world's ended episode is reported as
    Gymnasium reports it, in ``infos["episode"]`` (``r``: the return, per
    world the mean over its robots of their returns, which is the global
    return when every robot gets the same reward; ``l``: the length;
    ``t``: the time) masked by ``infos["_episode"]``, with
    ``return_queue``, ``length_queue`` and ``episode_count``. Gymnasium's
    own wrapper does the bookkeeping, for both autoreset modes."""

    def __init__(self, env: SwarmVectorEnv, buffer_length: int = 100, stats_key: str = "episode") -> None:
        super().__init__(env)
        self.statistics = RecordEpisodeStatistics(_WorldReward(env), buffer_length=buffer_length, stats_key=stats_key)

    @property
    def return_queue(self):
        return self.statistics.return_queue

    @property
    def length_queue(self):
        return self.statistics.length_queue

    @property
    def episode_count(self) -> int:
        return self.statistics.episode_count

    def reset(self, *, seed=None, options=None):
        return self.statistics.reset(seed=seed, options=options)

    def step(self, actions):
        obs, _, terminated, truncated, info = self.statistics.step(actions)
        return obs, info.pop("robot_rewards"), terminated, truncated, info


def make_single_agent_vector_env(
    num_envs: int = 1, max_episode_steps: int | None = None, **kwargs: Any
) -> SingleAgentVectorEnv:
    """``gymnasium.make_vec``'s entry point: the single-agent view of
    ``num_envs`` worlds; the spec's ``max_episode_steps`` truncates as
    ``max_steps`` does, unless ``max_steps`` is given."""
    if max_episode_steps is not None and kwargs.get("max_steps") is None:
        kwargs["max_steps"] = max_episode_steps
    return SwarmVectorEnv(num_envs, **kwargs).single_agent_view()
