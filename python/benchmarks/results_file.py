"""The benchmarks' results files: JSON written whole or not at all."""

from __future__ import annotations

import json
import os
from pathlib import Path


def write(path: str | Path, results: dict) -> None:
    """Writes `results` to `path` as JSON through a temporary file beside
    it, so that a failed write leaves the old file as it was."""
    path = Path(path)
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(json.dumps(results, indent=1) + "\n")
    os.replace(tmp, path)


def render_or_measure(args, measure, render) -> None:
    """A benchmark's command: with `--render FILE`, prints the markdown of
    that results file; else measures, writes the results to `--out` if
    given, and prints their markdown."""
    if args.render:
        print(render(json.loads(Path(args.render).read_text())), end="")
        return
    results = measure(args)
    if args.out:
        write(args.out, results)
    print(render(results), end="")
