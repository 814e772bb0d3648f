"""Execution time of every chapter notebook, against the 20 s per-chapter budget.

Usage: ``python benchmarks/run_all.py`` (or ``make benchmark``). Prints a table; asserts nothing
(timings on shared machines are noisy: read the ratios, not single digits).
"""

from __future__ import annotations

import time
from pathlib import Path

import nbformat

from quadlib.progress import switch_off
from quadlib.teaching.execution import notebook_client

switch_off()  # no progress bars in stored or timed outputs

NOTEBOOKS = Path(__file__).resolve().parent.parent / "notebooks"
BUDGET_S = 20.0


def execute_seconds(path: Path) -> float:
    nb = nbformat.read(path, as_version=4)
    client = notebook_client(nb, path.parent)
    start = time.perf_counter()
    client.execute()
    return time.perf_counter() - start


def main() -> None:
    rows = [(p.name, execute_seconds(p)) for p in sorted(NOTEBOOKS.glob("[0-9]*.ipynb"))]
    width = max(len(name) for name, _ in rows)
    print(f"{'notebook':<{width}} | {'seconds':>7} | {'/ budget':>8}")
    print("-" * (width + 22))
    for name, seconds in rows:
        print(f"{name:<{width}} | {seconds:7.1f} | {seconds / BUDGET_S:8.2f}")
    total = sum(s for _, s in rows)
    print("-" * (width + 22))
    print(f"{'total':<{width}} | {total:7.1f} | budget {BUDGET_S:.0f} s per chapter (includes kernel start-up)")


if __name__ == "__main__":
    main()
