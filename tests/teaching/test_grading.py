"""The student edition and the grader: a solution passes, a blank answer is "not set yet", a wrong
answer gets the check's feedback; and in every chapter, each exercise's blank answer fails its check
with "answer not set yet" and each listed wrong answer fails it with feedback."""

import copy
from pathlib import Path

import nbformat
import pytest

from quadlib.teaching.grading import (
    ANSWER_TAG,
    RUBRIC_TAG,
    SOLUTION_TAG,
    exercises,
    grade_notebook,
    mutation_run,
    student_edition,
)

NOTEBOOKS = Path(__file__).resolve().parents[2] / "notebooks"
CHAPTERS = sorted(p.name for p in NOTEBOOKS.glob("[0-9][0-9]_*.ipynb") if exercises(nbformat.read(p, as_version=4)))


def _chapter(name):
    return nbformat.read(NOTEBOOKS / name, as_version=4)


def test_the_student_edition_removes_the_solutions_and_rubrics_and_keeps_the_rest():
    full = _chapter("16_without_gps.ipynb")
    student = student_edition(full)
    nb = copy.deepcopy(full)  # the chapter without its rubrics, cell for cell the student edition's layout
    nb.cells = [c for c in nb.cells if RUBRIC_TAG not in c.metadata.get("tags", [])]
    assert len(nb.cells) < len(full.cells) and len(student.cells) == len(nb.cells), "the rubric was not dropped"
    found = exercises(nb)
    assert [e.answers for e in exercises(student)] == [e.answers for e in found]
    for ex in found:
        solution = nb.cells[ex.answer].source
        assert all(solution not in cell.source for cell in student.cells), "a solution survived"
        cell = student.cells[ex.answer]
        assert ANSWER_TAG in cell.metadata["tags"] and SOLUTION_TAG not in cell.metadata["tags"]
        assert all(name in cell.source for name in ex.answers) and cell.outputs == []
        assert student.cells[ex.check].outputs == [] and student.cells[ex.check].source == nb.cells[ex.check].source
    untouched = [i for i in range(len(nb.cells)) if i not in {i for e in found for i in (e.answer, e.check)}]
    assert all(student.cells[i] == nb.cells[i] for i in untouched)
    assert full.cells[exercises(full)[0].answer].source == nb.cells[found[0].answer].source  # the input is unchanged


def test_grading_passes_a_solution_fails_a_blank_and_explains_a_wrong_answer(tmp_path):
    nb = _chapter("01_averaging.ipynb")
    ex = exercises(nb)[0]
    nbformat.write(nb, tmp_path / "solution.ipynb")
    nbformat.write(student_edition(nb), tmp_path / "blank.ipynb")
    wrong = student_edition(nb)
    wrong.cells[ex.answer].source = "alpha_ex, lag_ex = 0.5, 1.0"
    nbformat.write(wrong, tmp_path / "wrong.ipynb")
    assert [g.passed for g in grade_notebook(tmp_path / "solution.ipynb")] == [True] * len(exercises(nb))
    blank = grade_notebook(tmp_path / "blank.ipynb")  # the whole student edition, as shipped
    assert len(blank) == len(exercises(nb)) and all(not g.passed and g.feedback.startswith("answer not set yet")
                                                    for g in blank), blank
    graded = grade_notebook(tmp_path / "wrong.ipynb")
    assert not graded[0].passed and "not set yet" not in graded[0].feedback and graded[0].feedback
    with pytest.raises(FileNotFoundError, match="path: expected a notebook file"):
        grade_notebook(tmp_path / "missing.ipynb")


@pytest.mark.parametrize("name", CHAPTERS)
def test_every_blank_and_every_wrong_answer_listed_is_rejected(name):
    """The mutation run: the blank answer of each exercise is "not set yet", and each plausible wrong
    answer in a solution's metadata fails its check with feedback."""
    tried = mutation_run(NOTEBOOKS / name)
    n_exercises = len(exercises(_chapter(name)))
    assert [m.number for m in tried if m.blank] == list(range(1, n_exercises + 1))
    assert len(tried) >= 3 * n_exercises, "list a few plausible wrong answers per exercise"
    accepted = [(m.number, m.source, m.feedback) for m in tried if not m.rejected]
    assert not accepted, f"answers the checks did not reject as they should: {accepted}"
