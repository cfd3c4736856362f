"""zumo_swarm: the zumo-swarm simulator (robots building shapes by pushing
pucks, guided by a projected scalar field) as Gymnasium and PettingZoo
environments. The simulation runs in Rust (the project's ``sim`` crate);
this package adds no simulation of its own.

- :func:`parallel_env`: PettingZoo ``ParallelEnv``, one agent per robot.
- :func:`vector_env`: many worlds stepped in Rust threads, NumPy arrays in
  and out (next-step autoreset); ``.single_agent_view()`` for Gymnasium tools.
- :func:`gym_env`: one world as a Gymnasium ``Env`` (the single-agent view:
  every robot's observation stacked, ``MultiDiscrete`` actions).
- :func:`export_policy` / :func:`load_policy`: policy blobs for ``host
  flash`` and back.

Settings (keyword arguments of every environment, as ``host run``'s flags):

- ``field="annulus"``: ``"annulus"``, ``"letter:T"`` (T, I, L, V, X, Z) or
  the path of a PNG/JPEG image;
- ``arena=None``: ``"thesis"`` (the reference model's 800 x 800 square) or
  ``"tv75"`` (the thesis' 75" TV lying flat, docs/robot-sensors.md); the
  default is ``"tv75"`` with ``sensors="robot"`` and ``"thesis"`` otherwise,
  as ``host run``;
- ``robots=None``, ``pucks=None``: the arena's counts (8 and 250 in the
  thesis' square, 5 and 12 on the TV);
- ``sensors="disc"``: ``"disc"`` (the reference model's discs),
  ``"disc-thesis"`` or ``"robot"`` (the Zumo's photo-transistors and Pixy
  camera through the firmware's arithmetic); ``robot_config``: the robot
  model's settings as a dict or a JSON file (docs/robot-sensors.md);
- ``seed=1``: the first world's seed, 0 to 2**63 - 1 (world ``i`` of a
  vector env gets ``seed + i``, which must not pass 2**63 - 1 either);
- ``max_steps=None``: truncate episodes after this many steps (they are
  always truncated at the stuck limit: 150,000 steps on the annulus,
  50,000 on letters and images);
- ``thresholds=None``: ``(outie, innie)`` field thresholds of the target
  shape (default 0.6, 0.8 on the annulus, 1, 1 on letters);
- ``reward="reference"``: ``"reference"``, ``"thesis"``, ``"collision"``,
  ``"collision-spread"`` (docs/training.md), ``"per-robot"`` (each robot
  the Eval change of the pucks it touched), ``"success"`` (1 when the
  shape forms) or ``"success-shaped"`` (success plus potential-based
  shaping on Eval, discounted by ``gamma=0.99``); docs/python.md says
  which to use for what (:func:`reward_value` computes one step's);
- ``observation="reading"``: ``"reading"`` (7 floats per robot: field
  left, mid, right, then puck left/right and obstacle left/right as 0/1)
  or ``"state"`` (the reading hashed by ``hasher``, a discrete state);
- ``hasher="original"``: ``"original"``, ``"original-obstacle"``,
  ``"bits7"``, ``"bits9"`` (checked whatever the observation;
  the role hashers ``"original-role"`` and ``"bits9-role"`` are refused: the
  environments have no innies);
- ``action="discrete"``: ``"discrete"`` (an index into ``actions``) or
  ``"continuous"`` (an angular speed, radians per step, clipped to the
  largest of ``actions``);
- ``actions=None``: the angular speeds, 2 to 4 (default 0.3, 0.15, -0.15,
  -0.3; positive turns right); ``forward_speed=2.0`` units per step;
- ``render_mode=None``, ``"rgb_array"`` (the picture ``host render``
  draws) or, for one world, ``"human"`` (the live view of ``host view``,
  served on loopback for the environment's own world, its address
  printed and in ``env.view_url``; docs/python.md), ``render_size=800``
  pixels.

A bad argument raises ``ValueError`` or ``TypeError`` naming it (a count
out of range in the words of the ranges table, docs/ranges.md); an
unknown keyword is refused with the closest valid name and the list.
``step()`` before the first ``reset()``, and ``step()`` or ``reset()``
after ``close()``, raise ``RuntimeError``.
"""

from __future__ import annotations

from typing import Any

import gymnasium

from zumo_swarm._native import DEFAULT_ANGULAR, DEFAULT_FORWARD_SPEED, HASHERS, READING_FIELDS, REWARDS, reward_value
from zumo_swarm.parallel import SwarmParallelEnv
from zumo_swarm.policy import Policy, export_policy, load_policy
from zumo_swarm.single import SwarmEnv
from zumo_swarm.vector import RecordRobotEpisodeStatistics, SingleAgentVectorEnv, SwarmVectorEnv

__all__ = [
    "DEFAULT_ANGULAR",
    "DEFAULT_FORWARD_SPEED",
    "HASHERS",
    "READING_FIELDS",
    "REWARDS",
    "Policy",
    "RecordRobotEpisodeStatistics",
    "SingleAgentVectorEnv",
    "SwarmEnv",
    "SwarmParallelEnv",
    "SwarmVectorEnv",
    "export_policy",
    "gym_env",
    "load_policy",
    "parallel_env",
    "reward_value",
    "vector_env",
]


def parallel_env(**settings: Any) -> SwarmParallelEnv:
    """A PettingZoo ``ParallelEnv`` of one world, one agent per robot."""
    return SwarmParallelEnv(**settings)


def vector_env(num_worlds: int, **settings: Any) -> SwarmVectorEnv:
    """``num_worlds`` worlds stepped in Rust threads (a Gymnasium
    ``VectorEnv`` with per-robot rewards), with Gymnasium's default
    next-step autoreset: a world's episode ends in one step, and its next
    step resets it (ignoring its actions) and returns the new episode's
    first observation with reward 0. ``autoreset_mode="same-step"`` and
    ``threads=N`` are also taken; see :class:`SwarmVectorEnv`."""
    return SwarmVectorEnv(num_worlds, **settings)


def gym_env(**settings: Any) -> SwarmEnv:
    """One world as a Gymnasium ``Env`` (the single-agent view)."""
    return SwarmEnv(**settings)


if "zumo_swarm/Swarm-v0" not in gymnasium.registry:
    gymnasium.register(
        id="zumo_swarm/Swarm-v0",
        entry_point="zumo_swarm.single:SwarmEnv",
        vector_entry_point="zumo_swarm.vector:make_single_agent_vector_env",
        # the default world's stuck limit (the annulus'); letters and images
        # truncate at their own 50,000 first
        max_episode_steps=150_000,
    )
