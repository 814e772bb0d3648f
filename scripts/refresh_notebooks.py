"""Execute chapter notebooks top to bottom and store them with outputs and normalised metadata.

Usage: ``python scripts/refresh_notebooks.py [notebooks/NN_name.ipynb ...]`` (default: all).
Run after editing a chapter, so that the outputs nbval compares are fresh,
counted 1, 2, 3 … and free of per-run metadata (timings, widget state).
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import nbformat

from quadlib.progress import switch_off
from quadlib.teaching.execution import notebook_client

switch_off()  # no progress bars in stored or timed outputs

NOTEBOOKS = Path(__file__).resolve().parent.parent / "notebooks"
KEEP_CELL_METADATA = ("tags", "jupyter", "editable", "deletable", "mutations")


def normalise(nb: nbformat.NotebookNode) -> None:
    nb.metadata = {
        "kernelspec": {"display_name": "Python 3", "language": "python", "name": "python3"},
        "language_info": {"name": "python", "pygments_lexer": "ipython3"},
    }
    for cell in nb.cells:
        cell.metadata = {k: v for k, v in cell.metadata.items() if k in KEEP_CELL_METADATA}
        if cell.cell_type == "code":
            cell.outputs = coalesced(cell.outputs)


def coalesced(outputs: list) -> list:
    """The outputs with each run of one stream's pieces joined: how a print is split depends on timing."""
    joined = []
    for out in outputs:
        last = joined[-1] if joined else None
        if out.output_type == "stream" and last is not None and last.output_type == "stream" and last.name == out.name:
            last.text += out.text
        else:
            joined.append(out)
    return joined


def refresh(path: Path) -> float:
    nb = nbformat.read(path, as_version=4)
    start = time.perf_counter()
    notebook_client(nb, path.parent).execute()
    elapsed = time.perf_counter() - start
    normalise(nb)
    nbformat.write(nb, path)
    return elapsed


if __name__ == "__main__":
    paths = [Path(p) for p in sys.argv[1:]] or sorted(NOTEBOOKS.glob("[0-9]*.ipynb"))
    for p in paths:
        print(f"{p.name}: executed in {refresh(p):.1f} s", flush=True)
