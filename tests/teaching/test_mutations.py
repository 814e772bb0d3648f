"""The mutation run of every chapter: each plausible wrong answer listed with a solution fails its
check. A module of its own, so that pytest-xdist (``--dist loadscope``) runs it on another worker
than the student-edition runs of ``test_grading.py``: each executes every chapter once."""

from pathlib import Path

import nbformat
import pytest

from quadlib.teaching.grading import exercises, mutation_run

NOTEBOOKS = Path(__file__).resolve().parents[2] / "notebooks"
CHAPTERS = sorted(p.name for p in NOTEBOOKS.glob("[0-9][0-9]_*.ipynb") if exercises(nbformat.read(p, as_version=4)))


@pytest.mark.parametrize("name", CHAPTERS)
def test_every_wrong_answer_listed_is_rejected(name):
    """The mutation run: each plausible wrong answer in a solution's metadata fails its check."""
    tried = mutation_run(NOTEBOOKS / name)
    graded = exercises(nbformat.read(NOTEBOOKS / name, as_version=4))
    assert len(tried) >= 2 * len(graded), "list a few plausible wrong answers per exercise"
    accepted = [(m.number, m.source) for m in tried if not m.rejected]
    assert not accepted, f"accepted wrong answers: {accepted}"
