"""The keyword arguments every environment takes, and the spaces they give.

The simulator settings (``field``, ``robots``, ``pucks``, ``sensors``,
``robot_config``, ``seed``, ``max_steps``, ``thresholds``, ``reward``,
``observation``, ``hasher``, ``action``, ``actions``, ``forward_speed``, and
every other setting of the world by its name, ``noise`` and ``walls`` among
them: :data:`zumo_swarm._native.WORLD_SETTINGS`) are checked in Rust by
:class:`zumo_swarm._native.Batch`; this module only brings Python values
into the types it takes and builds Gymnasium spaces from what the batch
reports.
"""

from __future__ import annotations

import difflib
import inspect
import json
import os
from collections.abc import Mapping
from typing import Any

import numpy as np
from gymnasium import spaces

from zumo_swarm._native import SEED_RANGE, WORLD_SETTINGS, Batch

#: Render modes of every environment: the picture ``host render`` draws.
RENDER_MODES = ["rgb_array"]

#: Render modes of the environments of one world: also ``"human"``, the
#: live view in a browser (docs/view.md).
ONE_WORLD_RENDER_MODES = ["rgb_array", "human"]

#: The simulator settings every environment takes: the native batch's
#: keyword arguments, less those the environments set themselves, and the
#: world's settings it takes by name.
SETTINGS = tuple(
    name for name in inspect.signature(Batch).parameters if name not in ("num_worlds", "autoreset", "threads", "world")
) + tuple(name for name in WORLD_SETTINGS if name not in inspect.signature(Batch).parameters)

#: Settings that are whole numbers (``None`` for the default); the seed is
#: checked by :func:`check_seed`.
WHOLE_NUMBERS = ("robots", "pucks", "max_steps")

#: The largest seed: seeds are 64-bit signed integers, as NumPy's are.
MAX_SEED = 2**63 - 1


def check_whole(name: str, value: Any) -> int:
    """``value`` a whole number of 64 bits (signed); the simulator checks
    its range, as its table of ranges words it."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise TypeError(f"{name} = {value!r}: expected a whole number")
    if not -(2**63) <= int(value) <= 2**63 - 1:
        raise ValueError(f"{name} = {value}: not a 64-bit whole number (-2**63 to 2**63 - 1)")
    return int(value)


def check_seed(value: Any) -> int:
    """``value`` a seed, 0 to :data:`MAX_SEED` (the simulator checks the
    seeds of the other worlds of a vector env with the same words)."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise TypeError(f"seed = {value!r}: expected a whole number")
    if not 0 <= int(value) <= MAX_SEED:
        raise ValueError(f"seed = {value}: {SEED_RANGE}")
    return int(value)


def check_names(settings: Mapping[str, Any], own: tuple[str, ...]) -> None:
    """Every keyword a setting of the simulator or one of the
    environment's ``own``; an unknown one is refused with the closest
    valid name and the list."""
    valid = SETTINGS + own
    for name in settings:
        if name not in SETTINGS:
            close = difflib.get_close_matches(name, valid, n=1)
            hint = f" (did you mean {close[0]!r}?)" if close else ""
            raise TypeError(f"unknown keyword argument {name!r}{hint}: the environment takes {', '.join(valid)}")


def make_batch(
    num_worlds: int, autoreset: str, threads: int | None, settings: dict[str, Any], own: tuple[str, ...]
) -> Batch:
    """A batch of ``num_worlds`` worlds with the environment's settings;
    ``own`` names the environment's own keywords (for the message that
    refuses an unknown one)."""
    check_names(settings, own)
    check_whole("num_worlds", num_worlds)
    if threads is not None:
        check_whole("threads", threads)
    settings = dict(settings)
    for name in WHOLE_NUMBERS:
        if settings.get(name) is not None:
            settings[name] = check_whole(name, settings[name])
    if "seed" in settings:
        settings["seed"] = check_seed(settings["seed"])
    config = settings.get("robot_config")
    if isinstance(config, Mapping):
        settings["robot_config"] = json.dumps(config)
    elif isinstance(config, (str, os.PathLike)):
        with open(config, encoding="utf-8") as f:
            settings["robot_config"] = f.read()
    elif config is not None:
        raise TypeError(f"robot_config = {config!r}: expected a dict of settings or the path of a JSON file")
    thresholds = settings.get("thresholds")
    if thresholds is not None:
        try:
            outie, innie = (float(t) for t in thresholds)
        except (TypeError, ValueError):
            raise ValueError(f"thresholds = {thresholds!r}: must be two numbers (outie, innie)") from None
        settings["thresholds"] = (outie, innie)
    if "actions" in settings and settings["actions"] is not None:
        settings["actions"] = [float(a) for a in settings["actions"]]
    return Batch(num_worlds, autoreset=autoreset, threads=threads, **settings)


def check_render(render_mode: str | None, render_size: int, modes: list[str] = RENDER_MODES) -> tuple[str | None, int]:
    """``render_mode`` ``None`` or one of ``modes``, ``render_size`` 16 to 4096
    pixels; anything else is refused by name."""
    if render_mode is not None and render_mode not in modes:
        expected = " or ".join(["None"] + [repr(m) for m in modes])
        raise ValueError(f"render_mode = {render_mode!r}: expected {expected}")
    if not isinstance(render_size, (int, np.integer)) or not 16 <= render_size <= 4096:
        raise ValueError(f"render_size = {render_size!r}: must be a whole number of pixels from 16 to 4096")
    return render_mode, int(render_size)


def robot_observation_space(batch: Batch) -> spaces.Space:
    """One robot's observation: 7 floats in [0, 1], or a hashed state."""
    if batch.num_states is None:
        return spaces.Box(0.0, 1.0, shape=(7,), dtype=np.float32)
    return spaces.Discrete(batch.num_states)


def robot_action_space(batch: Batch) -> spaces.Space:
    """One robot's action: an action-table index, or an angular speed."""
    if batch.action == "discrete":
        return spaces.Discrete(len(batch.angular_speeds))
    return spaces.Box(-batch.max_turn, batch.max_turn, shape=(1,), dtype=np.float32)


def world_observation_space(batch: Batch) -> spaces.Space:
    """Every robot's observation of one world, stacked."""
    if batch.num_states is None:
        return spaces.Box(0.0, 1.0, shape=(batch.robots, 7), dtype=np.float32)
    return spaces.MultiDiscrete(np.full(batch.robots, batch.num_states, dtype=np.int64))


def world_action_space(batch: Batch) -> spaces.Space:
    """Every robot's action of one world: one shared policy acts for all."""
    if batch.action == "discrete":
        return spaces.MultiDiscrete(np.full(batch.robots, len(batch.angular_speeds), dtype=np.int64))
    return spaces.Box(-batch.max_turn, batch.max_turn, shape=(batch.robots,), dtype=np.float32)


def flat_actions(batch: Batch, actions: Any, shape: tuple[int, ...]) -> np.ndarray:
    """``actions`` as the flat array the batch takes, its shape and type checked."""
    a = np.asarray(actions)
    if a.shape != shape:
        raise ValueError(f"actions: expected an array of shape {shape}, got shape {a.shape}")
    if batch.action == "discrete":
        if not np.issubdtype(a.dtype, np.integer):
            raise TypeError(f"actions: expected integers (action-table indices), got dtype {a.dtype}")
        return np.ascontiguousarray(a, dtype=np.int64).reshape(-1)
    if not (np.issubdtype(a.dtype, np.floating) or np.issubdtype(a.dtype, np.integer)):
        raise TypeError(f"actions: expected angular speeds (floats), got dtype {a.dtype}")
    return np.ascontiguousarray(a, dtype=np.float64).reshape(-1)


def world_info(info: dict[str, np.ndarray], world: int) -> dict[str, Any]:
    """One world's entries of a batch's info, as Python scalars."""
    return {key: value[world].item() for key, value in info.items() if not key.startswith("_") and key != "final_obs"}


class Lifecycle:
    """The order of calls Gymnasium and PettingZoo define, enforced:
    ``reset()`` before the first ``step()``, and neither after ``close()``
    (a closed environment has let its live view go)."""

    _reset_done = False
    _closed = False

    def _check_open(self, call: str) -> None:
        """Refuses ``call`` on a closed environment."""
        if self._closed:
            raise RuntimeError(f"{call}() after close(): the environment is closed; make a new one")

    def _check_step(self) -> None:
        """Refuses a step before the first reset or after close."""
        self._check_open("step")
        if not self._reset_done:
            raise RuntimeError("step() before reset(): call reset() first, as Gymnasium and PettingZoo ask")

    def _was_reset(self) -> None:
        """Notes a reset: steps may follow."""
        self._reset_done = True


class OneWorld(Lifecycle):
    """What the environments of one world share: drawing it, its live view
    and its bodies (the class has ``_batch``, ``render_mode`` and
    ``render_size``)."""

    #: The live view's address with ``render_mode="human"``, else None.
    view_url: str | None = None

    def _start_view(self) -> None:
        """With ``render_mode="human"``: serves the live view of this world
        on loopback (any free port), every step and reset shown, and prints
        its address once."""
        if self.render_mode == "human":
            self.view_url = self._batch.serve_view()
            print(f"zumo_swarm: live view at {self.view_url}", flush=True)

    def render(self):
        """The world as ``host render`` draws it (``render_mode="rgb_array"``);
        None with ``"human"`` (the live view shows every step by itself) or
        no render mode."""
        if self.render_mode in (None, "human"):
            return None
        return self._batch.render(0, self.render_size)

    def close(self) -> None:
        """Stops the live view, if one is served; the environment takes no
        more steps nor resets."""
        self._batch.close_view()
        self.view_url = None
        self._closed = True

    def positions(self):
        """Bodies' positions (robots first, then pucks) and the robots' headings."""
        return self._batch.positions(0)
