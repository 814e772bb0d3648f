"""One benchmark's table for two checkouts of the project, measured in one run, side by side.

Usage: ``python benchmarks/compare_revisions.py BEFORE_DIR [SCRIPT] [ROUNDS]``, from this checkout,
with ``BEFORE_DIR`` another checkout (``git worktree add --detach ../before <commit>``; run its
``make`` or one benchmark there first, so that its numba cache is compiled). ``SCRIPT`` is a
benchmark that prints ``name | value | ratio`` rows (``benchmarks/estimator_cost.py`` by default),
each checkout runs its own copy, alternately, ``ROUNDS`` times (2 by default), and each row keeps its
best value. A row that one checkout's script does not print shows ``—``.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def table(checkout: Path, script: str) -> dict[str, float]:
    """``name → value`` of the rows the checkout's copy of ``script`` prints."""
    env = dict(os.environ, PYTHONPATH=str(checkout))
    out = subprocess.run([sys.executable, str(checkout / script)], cwd=checkout, env=env, check=True,
                         capture_output=True, text=True).stdout
    rows = {}
    for line in out.splitlines():
        cells = [c.strip() for c in line.split("|")]
        if len(cells) >= 2:
            try:
                rows[cells[0]] = float(cells[1])
            except ValueError:
                continue  # the header
    return rows


def main(before: str, script: str = "benchmarks/estimator_cost.py", rounds: str = "2") -> None:
    checkouts = {"before": Path(before).resolve(), "after": ROOT}
    for name, path in checkouts.items():
        if not (path / script).is_file():
            raise SystemExit(f"{name}: no {script} in {path}")
    best: dict[str, dict[str, float]] = {"before": {}, "after": {}}
    for _ in range(int(rounds)):
        for name, path in checkouts.items():
            for row, value in table(path, script).items():
                best[name][row] = min(value, best[name].get(row, value))
    names = list(best["before"]) + [r for r in best["after"] if r not in best["before"]]
    width = max(len(n) for n in names)
    print(f"{script}: before = {checkouts['before']}, after = {checkouts['after']}, best of {rounds} rounds each")
    print(f"{'row':<{width}} | {'before':>8} | {'after':>8} | {'after / before':>14}")
    for row in names:
        b, a = best["before"].get(row), best["after"].get(row)
        ratio = f"{a / b:14.2f}" if a is not None and b is not None else f"{'—':>14}"
        cells = [f"{v:8.1f}" if v is not None else f"{'—':>8}" for v in (b, a)]
        print(f"{row:<{width}} | {cells[0]} | {cells[1]} | {ratio}")


if __name__ == "__main__":
    main(*sys.argv[1:4])
