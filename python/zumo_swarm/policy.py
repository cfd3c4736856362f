"""Policy blobs from Python: a greedy table learned here written in the
format ``host policy inspect`` reads and ``host flash`` puts on a robot,
and a blob read back."""

from __future__ import annotations

import os
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from zumo_swarm import _native


@dataclass(frozen=True)
class Policy:
    """A decoded policy blob: every state's best actions (``sets``, bit
    masks: bit ``a`` for action ``a``; the robot picks among them with its
    generator, docs/flashed.md), the lowest of them (``table``), and what it
    was trained for (``trained_for``: ``(sensors, arena)``, ``None`` for a
    blob of format version 1)."""

    hasher: str
    actions: tuple[float, ...]
    forward_speed: float
    table: np.ndarray
    sets: np.ndarray
    field: str
    name: str
    trainer_steps: int
    seed: int
    trained_for: tuple[str, str] | None
    version: int

    def act(self, states: Any) -> np.ndarray:
        """Each hashed state's lowest best action (any shape)."""
        return self.table[np.asarray(states)]


def load_policy(path: str | os.PathLike) -> Policy:
    """Reads a policy blob file (``host train``'s, or :func:`export_policy`'s)."""
    path = Path(path)
    fields = _native.decode_policy(path.read_bytes(), str(path))
    fields["actions"] = tuple(fields["actions"])
    return Policy(**fields)


def _choices(table: Any) -> dict[str, list[int]]:
    """``table`` as :func:`_native.encode_policy` takes it: a Q-table's
    best actions per state as bit masks (every action equal to the state's
    greatest value: the learner's choice among equals, kept for the robot),
    or one action per state."""
    t = np.asarray(table)
    if t.ndim == 2:
        if not np.issubdtype(t.dtype, np.number) or not np.all(np.isfinite(t)):
            raise ValueError("table: a Q-table (states x actions) must hold finite numbers")
        if t.shape[1] > 4:
            raise ValueError(f"table: a Q-table has at most 4 actions, got {t.shape[1]}")
        best = t == t.max(axis=1, keepdims=True)
        masks = (best * (1 << np.arange(t.shape[1]))).sum(axis=1)
        return {"sets": [int(m) for m in masks]}
    if t.ndim == 1:
        if not np.issubdtype(t.dtype, np.integer):
            raise TypeError(f"table: a greedy table holds action indices (integers), got dtype {t.dtype}")
        return {"table": [int(a) for a in t]}
    raise ValueError(f"table: expected a Q-table (states x actions) or one action per state, got shape {t.shape}")


def export_policy(
    path: str | os.PathLike,
    table: Any,
    *,
    env: Any = None,
    hasher: str | None = None,
    actions: Any = None,
    forward_speed: float | None = None,
    field: str | None = None,
    name: str | None = None,
    trainer_steps: int = 0,
    seed: int = 0,
) -> Path:
    """Writes ``table`` as a policy blob at ``path`` (atomically: a reader
    sees the old file or the new one) and returns the path.

    ``table`` is a Q-table (states x actions: each state's best actions,
    all of them where several are equal, which the robot picks among as the
    learner did) or one action index per state. The hasher, actions,
    forward speed and field default to ``env``'s (any environment of this
    package built with ``observation="state"``), else to the thesis'
    (``original``, the four default actions at speed 2, annulus); ``name``
    to the file's stem. With ``env`` the blob records its sensor model and
    arena (``host run`` and ``host render`` warn, ``host flash`` refuses,
    on a mismatch). The blob is of format version 2 when a state has
    several best actions or the blob records what it was trained for,
    else version 1.
    """
    path = Path(path)
    batch = getattr(getattr(env, "unwrapped", env), "_batch", None) if env is not None else None
    if env is not None and batch is None:
        raise TypeError(f"env = {env!r}: not an environment of zumo_swarm")
    env_settings = getattr(getattr(env, "unwrapped", env), "settings", {}) if env is not None else {}
    if hasher is None:
        hasher = (batch.hasher if batch is not None else None) or "original"
    if actions is None:
        actions = batch.angular_speeds if batch is not None else _native.DEFAULT_ANGULAR
    if forward_speed is None:
        forward_speed = batch.forward_speed if batch is not None else _native.DEFAULT_FORWARD_SPEED
    if field is None:
        field = env_settings.get("field", "annulus")
    data = _native.encode_policy(
        **_choices(table),
        trained_for=batch.trained_for if batch is not None else None,
        hasher=hasher,
        actions=[float(a) for a in actions],
        forward_speed=float(forward_speed),
        field=str(field),
        name=path.stem if name is None else name,
        trainer_steps=int(trainer_steps),
        seed=int(seed),
    )
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path
