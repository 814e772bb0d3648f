"""Write the student edition of every chapter: solutions replaced by empty answer cells.

Usage: ``python scripts/student_edition.py OUT_DIR`` (``make student`` runs it and builds the
student book from its output). See :mod:`quadlib.teaching.grading`.
"""

from __future__ import annotations

import sys
from pathlib import Path

import nbformat

from quadlib.teaching.grading import student_edition

NOTEBOOKS = Path(__file__).resolve().parent.parent / "notebooks"


def main(out_dir: Path) -> None:
    out_dir.mkdir(parents=True, exist_ok=True)
    for path in sorted(NOTEBOOKS.glob("[0-9]*.ipynb")):
        nbformat.write(student_edition(nbformat.read(path, as_version=4)), out_dir / path.name)
        print(f"{path.name} -> {out_dir / path.name}")


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: python scripts/student_edition.py OUT_DIR")
    main(Path(sys.argv[1]))
