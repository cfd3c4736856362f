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
    """A decoded policy blob: the greedy action of every state."""

    hasher: str
    actions: tuple[float, ...]
    forward_speed: float
    table: np.ndarray
    field: str
    name: str
    trainer_steps: int
    seed: int

    def act(self, states: Any) -> np.ndarray:
        """The greedy actions of hashed states (any shape)."""
        return self.table[np.asarray(states)]


def load_policy(path: str | os.PathLike) -> Policy:
    """Reads a policy blob file (``host train``'s, or :func:`export_policy`'s)."""
    path = Path(path)
    fields = _native.decode_policy(path.read_bytes(), str(path))
    fields["actions"] = tuple(fields["actions"])
    return Policy(**fields)


def _greedy(table: Any) -> np.ndarray:
    t = np.asarray(table)
    if t.ndim == 2:
        if not np.issubdtype(t.dtype, np.number) or not np.all(np.isfinite(t)):
            raise ValueError("table: a Q-table (states x actions) must hold finite numbers")
        # The first best action, as the trainer's greedy policy picks it.
        return np.argmax(t, axis=1).astype(np.int64)
    if t.ndim == 1:
        if not np.issubdtype(t.dtype, np.integer):
            raise TypeError(f"table: a greedy table holds action indices (integers), got dtype {t.dtype}")
        return t.astype(np.int64)
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

    ``table`` is a Q-table (states x actions: its greedy policy, the first
    best action of each state) or one action index per state. The hasher,
    actions, forward speed and field default to ``env``'s (any environment
    of this package built with ``observation="state"``), else to the
    thesis' (``original``, the four default actions at speed 2, annulus);
    ``name`` to the file's stem.
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
        [int(a) for a in _greedy(table)],
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
