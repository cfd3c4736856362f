"""What the neural examples log, as CleanRL logs it, and the held-out
evaluation each of them ends with.

A run's directory (``out/runs/EXAMPLE__SEED__TIME`` by default, CleanRL's
naming) holds:

- ``scalars.csv``: a header line ``global_step,tag,value,wall_time``, then
  one line a scalar as it is logged (appended and flushed line by line, so
  a stopped run keeps what it logged): the world-steps so far (all worlds
  together), CleanRL's tag (``charts/episodic_return``,
  ``charts/episodic_length``, ``charts/SPS``, ``losses/value_loss`` ...,
  ``eval/formations``), the value, and the seconds since the run began;
- TensorBoard's event files with the same scalars, when TensorBoard is
  installed (``pip install tensorboard``; then ``tensorboard --logdir
  out/runs``); without it the CSV alone, and the run says so once;
- ``config.json``: the run's settings; ``summary.json``: its summary
  (both written whole, atomically).

:func:`evaluate` runs a greedy table on the evaluation seeds (1001 to
1010, none of them a training seed), as ``python/benchmarks/learning.py``
measures the tables of docs/python-results.md.
"""

from __future__ import annotations

import csv
import json
import os
import time
from pathlib import Path

import zumo_swarm

#: The held-out evaluation's seeds: no example trains on them.
EVAL_SEEDS = list(range(1001, 1011))


def evaluate(act, steps: int, seeds=EVAL_SEEDS, **settings) -> dict:
    """``act(states)`` (worlds x robots hashed states to action indices)
    run for ``steps`` steps on each of ``seeds`` at once: formations in
    all, the mean over seeds of the last Eval and of the mean Eval at the
    formation checks."""
    env = zumo_swarm.vector_env(len(seeds), observation="state", **settings)
    obs, _ = env.reset(seed=list(seeds))
    for _ in range(steps):
        obs, _, _, _, info = env.step(act(obs))
    return {
        "formations": int(info["formations"].sum()),
        "final_eval": float(info["eval"].mean()),
        "mean_eval": float(info["mean_eval"].mean()),
    }


def write_json(path: Path, value) -> None:
    """``value`` as JSON at ``path``, written whole or not at all."""
    tmp = path.with_name(f".{path.name}.tmp")
    tmp.write_text(json.dumps(value, indent=1) + "\n")
    os.replace(tmp, path)


def tensorboard_writer(directory: Path):
    """TensorBoard's ``SummaryWriter`` on ``directory``, or None when
    TensorBoard (or PyTorch) is not installed."""
    try:
        from torch.utils.tensorboard import SummaryWriter
    except ImportError:
        return None
    return SummaryWriter(str(directory))


class RunLog:
    """One run's scalars, settings and summary (module docs)."""

    def __init__(self, example: str, config: dict, run_dir: str | None = None) -> None:
        seed = config.get("seed", 0)
        self.dir = Path(run_dir or f"out/runs/{example}__{seed}__{int(time.time())}")
        self.dir.mkdir(parents=True, exist_ok=True)
        self.example, self.start = example, time.perf_counter()
        write_json(self.dir / "config.json", config)
        self._file = open(self.dir / "scalars.csv", "w", newline="", encoding="utf-8")
        self._csv = csv.writer(self._file)
        self._csv.writerow(["global_step", "tag", "value", "wall_time"])
        self._file.flush()
        self.tensorboard = tensorboard_writer(self.dir)
        if self.tensorboard is None:
            print(f"{example}: TensorBoard is not installed: logging to {self.dir / 'scalars.csv'} only", flush=True)
        else:
            self.tensorboard.add_text("hyperparameters", "\n".join(f"|{k}|{v}|" for k, v in config.items()))

    def scalar(self, tag: str, value: float, step: int) -> None:
        """Logs ``value`` of ``tag`` at world-step ``step``."""
        self._csv.writerow([step, tag, float(value), round(time.perf_counter() - self.start, 3)])
        self._file.flush()
        if self.tensorboard is not None:
            self.tensorboard.add_scalar(tag, value, step)

    def seconds(self) -> float:
        """Seconds since the run began."""
        return time.perf_counter() - self.start

    def finish(self, summary: dict) -> None:
        """Prints ``summary`` (with where the log is), keeps it in
        ``summary.json`` and closes the log."""
        summary = {**summary, "log": str(self.dir) + (" (scalars.csv, TensorBoard)" if self.tensorboard else " (scalars.csv)")}
        print(f"summary of {self.example}:", flush=True)
        for key, value in summary.items():
            print(f"  {key}: {value}", flush=True)
        write_json(self.dir / "summary.json", summary)
        self._file.close()
        if self.tensorboard is not None:
            self.tensorboard.close()


def held_out(act, steps: int, log: RunLog, step: int, **settings) -> str:
    """Evaluates ``act`` on the evaluation seeds (:func:`evaluate`), logs
    the figures as ``eval/...`` at world-step ``step`` and returns them as
    the summary's line."""
    result = evaluate(act, steps, **settings)
    for key, value in result.items():
        log.scalar(f"eval/{key}", value, step)
    return (
        f"{result['formations']} formations, final Eval {result['final_eval']:.4f}, mean Eval at checks "
        f"{result['mean_eval']:.4f} (greedy table, seeds {EVAL_SEEDS[0]} to {EVAL_SEEDS[-1]}, {steps:,} steps each)"
    )
