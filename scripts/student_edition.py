"""Write the student edition of the chapters with otter-grader, and what grading them needs.

Usage: ``python scripts/student_edition.py OUT_DIR [notebooks/NN_name.ipynb ...]`` (default: every
chapter; ``make student`` runs it and builds the student book from ``OUT_DIR/notebooks``). Each
chapter goes through :func:`quadlib.teaching.assignments.build_assignment`: ``OUT_DIR/notebooks``
(the student edition), ``OUT_DIR/autograder`` (otter's autograders), ``OUT_DIR/solved`` (the
student edition with the solutions filled in), and ``OUT_DIR/points.csv`` (every question's points,
and whether it is graded by hand).
"""

from __future__ import annotations

import csv
import sys
from pathlib import Path

from quadlib.teaching.assignments import build_assignment

NOTEBOOKS = Path(__file__).resolve().parent.parent / "notebooks"


def main(out_dir: Path, chapters: list[Path]) -> None:
    rows = []
    for chapter in chapters:
        questions = build_assignment(chapter, out_dir)
        rows += [(chapter.stem, q, p, "by hand" if manual else "autograded") for q, p, manual in questions]
        print(f"{chapter.name}: {len(questions)} questions, {sum(p for _, p, _ in questions)} points")
    with (out_dir / "points.csv").open("w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(["chapter", "question", "points", "graded"])
        writer.writerows(rows)
    print(f"student edition: {out_dir / 'notebooks'}; autograders: {out_dir / 'autograder'}")


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit("usage: python scripts/student_edition.py OUT_DIR [notebooks/NN_name.ipynb ...]")
    main(Path(sys.argv[1]), [Path(p) for p in sys.argv[2:]] or sorted(NOTEBOOKS.glob("[0-9]*.ipynb")))
