"""The chapters' graded exercises keep their shape (:mod:`quadlib.teaching.grading`): each solution
is followed by a check that first says "answer not set yet" for every answer the exercise asks for
(the public test of the student edition) and then asserts something about the answer (its hidden
test); the solution is collapsed in the book."""

import re
from pathlib import Path

import nbformat
import pytest

from quadlib.teaching.assignments import otter_master
from quadlib.teaching.grading import RUBRIC_TAG, exercises

NOTEBOOKS = sorted((Path(__file__).resolve().parents[1] / "notebooks").glob("[0-9][0-9]_*.ipynb"))
CASES = [(p.name, ex, nb) for p in NOTEBOOKS for nb in [nbformat.read(p, as_version=4)] for ex in exercises(nb)]


def test_every_chapter_from_01_has_three_graded_exercises():
    chapters = sorted(p.name for p in NOTEBOOKS if not p.name.startswith(("00", "9")))
    counts = {name: sum(case[0] == name for case in CASES) for name in chapters}
    assert all(n >= 3 for n in counts.values()), {name: n for name, n in counts.items() if n < 3}


@pytest.mark.parametrize(("name", "ex", "nb"), CASES, ids=[f"{c[0]}:{c[1].answer}" for c in CASES])
def test_a_solution_is_collapsed_and_followed_by_a_guarded_check(name, ex, nb):
    assert "hide-input" in nb.cells[ex.answer].metadata.get("tags", []), "the book must collapse the solution"
    check = nb.cells[ex.check]
    assert check.cell_type == "code", "the cell after a solution must be its check"
    assert ex.answers, "the statement names no answer (in backticks) that the solution defines"
    for answer in ex.answers:
        guard = re.search(rf'assert "{answer}" in globals\(\), "answer not set yet: [^"]*{answer}', check.source)
        assert guard, f"no 'answer not set yet' guard for {answer}"
    body = re.sub(r"(?m)^.*answer not set yet.*$", "", check.source)
    assert re.search(r"(?m)^\s*assert ", body), "the check asserts nothing about the answer"


OPEN = [(p.name, i, nb) for p in NOTEBOOKS for nb in [nbformat.read(p, as_version=4)]
        for i, c in enumerate(nb.cells) if c.cell_type == "markdown" and "(Open.)" in c.source]


def test_every_chapter_from_01_has_an_open_question():
    chapters = {p.name for p in NOTEBOOKS if not p.name.startswith(("00", "9"))}
    assert chapters <= {name for name, _, _ in OPEN}, chapters - {name for name, _, _ in OPEN}


@pytest.mark.parametrize(("name", "index", "nb"), OPEN, ids=[f"{c[0]}:{c[1]}" for c in OPEN])
def test_an_open_question_is_followed_by_a_collapsed_rubric_the_student_edition_drops(name, index, nb):
    rubric = nb.cells[index + 1]
    assert rubric.cell_type == "markdown" and RUBRIC_TAG in rubric.metadata.get("tags", []), "no rubric cell"
    assert rubric.source.startswith("<details>") and rubric.source.rstrip().endswith("</details>"), "not collapsed"
    points = re.findall(r"\*\*(\d+) points?\*\*", rubric.source)
    assert len(points) >= 3, "a rubric lists at least three criteria with their points"
    assert (rubric.source.count("(Open.)"), nb.cells[index].source.count("(Open.)")) == (0, 1), "one question per cell"
    master = otter_master(nb, name[:-6])  # the rubric is the manual question's solution: otter keeps it out
    k = next(i for i, c in enumerate(master.cells) if c.source == rubric.source)
    assert master.cells[k - 1].source == "# BEGIN SOLUTION" and master.cells[k + 1].source == "# END SOLUTION"
