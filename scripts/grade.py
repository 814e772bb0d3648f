"""Grade a folder of submitted chapters with the instructor's tests, into a score table.

Usage: ``python scripts/grade.py SUBMISSIONS_DIR [--autograders DIR] [--cell-timeout S]
[--submission-timeout S]`` (``make grade SUBMISSIONS=…``); see :mod:`quadlib.teaching.autograde`.
The autograders are ``make student``'s (default ``_build/student/autograder``); the scores go to
``SUBMISSIONS_DIR/scores.csv``.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from quadlib.progress import switch_off
from quadlib.teaching.autograde import grade_folder

switch_off()  # no progress bars in the graded runs

ROOT = Path(__file__).resolve().parent.parent

if __name__ == "__main__":
    parser = argparse.ArgumentParser(description="Grade submitted chapters with the instructor's tests.")
    parser.add_argument("submissions", type=Path)
    parser.add_argument("--autograders", type=Path, default=ROOT / "_build" / "student" / "autograder")
    parser.add_argument("--cell-timeout", type=int, default=120, help="seconds one cell may run [120]")
    parser.add_argument("--submission-timeout", type=int, default=1200, help="seconds one submission may run [1200]")
    a = parser.parse_args()
    scores = grade_folder(a.submissions, a.autograders, a.cell_timeout, a.submission_timeout, log=print)
    print(f"scores: {scores}")
