"""Grade a folder of submitted chapter notebooks into a score table with per-exercise feedback.

Usage: ``python scripts/grade.py SUBMISSIONS_DIR [SCORES_CSV]`` (``make grade SUBMISSIONS=…``).
Every ``*.ipynb`` below the folder is executed top to bottom (a failing cell does not stop the
run) and each exercise's check decides (:func:`quadlib.teaching.grading.grade_notebook`). The
table goes to the screen and to ``SCORES_CSV`` (default ``SUBMISSIONS_DIR/scores.csv``), one row
per submission and exercise.
"""

from __future__ import annotations

import csv
import sys
from pathlib import Path

from quadlib.progress import switch_off
from quadlib.teaching.grading import grade_notebook

switch_off()  # no progress bars in stored or timed outputs


def main(folder: Path, scores: Path) -> None:
    submissions = sorted(p for p in folder.rglob("*.ipynb") if ".ipynb_checkpoints" not in p.parts)
    if not submissions:
        sys.exit(f"no notebooks found below {folder}")
    rows = []
    for path in submissions:
        grades = grade_notebook(path)
        passed = sum(g.passed for g in grades)
        print(f"{path.relative_to(folder)}: {passed} of {len(grades)} exercises passed")
        for g in grades:
            print(f"  {g.number}. {'passed' if g.passed else 'FAILED'}{'' if g.passed else ': ' + g.feedback}")
            rows.append({"submission": str(path.relative_to(folder)), "exercise": g.number,
                         "passed": int(g.passed), "feedback": g.feedback})
    with scores.open("w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=["submission", "exercise", "passed", "feedback"])
        writer.writeheader()
        writer.writerows(rows)
    print(f"scores: {scores}")


if __name__ == "__main__":
    if len(sys.argv) not in (2, 3):
        sys.exit("usage: python scripts/grade.py SUBMISSIONS_DIR [SCORES_CSV]")
    folder = Path(sys.argv[1])
    main(folder, Path(sys.argv[2]) if len(sys.argv) == 3 else folder / "scores.csv")
