"""The student edition and the grader: a solution passes, a blank answer is "not set yet", a wrong
answer gets the check's feedback. The tools that prove the checks — the nbval plugin that tries each
exercise's blank and listed wrong answers in every chapter's nbval run, and :func:`mutation_run` —
pass good checks and catch each kind of bad one."""

import copy
import re
import subprocess
import sys
from pathlib import Path

import nbformat
import pytest

from quadlib.teaching.grading import (
    ANSWER_TAG,
    RUBRIC_TAG,
    SOLUTION_TAG,
    Grade,
    exercises,
    grade_notebook,
    mutation_run,
    student_edition,
)

NOTEBOOKS = Path(__file__).resolve().parents[2] / "notebooks"


def _chapter(name):
    return nbformat.read(NOTEBOOKS / name, as_version=4)


def test_the_student_edition_removes_the_solutions_and_rubrics_and_keeps_the_rest():
    full = _chapter("19_without_gps.ipynb")
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
    _exercise_notebook(tmp_path / "solution.ipynb", [])
    wrong = nbformat.read(tmp_path / "solution.ipynb", as_version=4)
    wrong.cells[2].source = "area = 3.0"
    nbformat.write(student_edition(wrong), tmp_path / "blank.ipynb")
    nbformat.write(wrong, tmp_path / "wrong.ipynb")
    assert grade_notebook(tmp_path / "solution.ipynb") == [Grade(1, True, "passed")]
    assert grade_notebook(tmp_path / "wrong.ipynb") == [Grade(1, False, "area: not the area of a unit circle")]
    assert grade_notebook(tmp_path / "blank.ipynb") == [Grade(1, False, "answer not set yet: define area")]
    with pytest.raises(FileNotFoundError, match="path: expected a notebook file"):
        grade_notebook(tmp_path / "missing.ipynb")


def test_the_student_edition_of_a_chapter_says_answer_not_set_yet_to_each_blank(tmp_path):
    nb = _chapter("01_averaging.ipynb")
    nbformat.write(student_edition(nb), tmp_path / "blank.ipynb")
    blank = grade_notebook(tmp_path / "blank.ipynb")  # the whole student edition, as shipped
    assert len(blank) == len(exercises(nb)) == 3 and all(not g.passed and g.feedback.startswith("answer not set yet")
                                                         for g in blank), blank


CHECK = ('assert "area" in globals(), "answer not set yet: define area"\n'
         'assert abs(area - math.pi) < 1e-9, "area: not the area of a unit circle"')


def _exercise_notebook(path, mutations, check=CHECK):
    nb = nbformat.v4.new_notebook()
    solution = nbformat.v4.new_code_cell("area = math.pi", metadata={"tags": ["solution"], "mutations": mutations})
    nb.cells = [nbformat.v4.new_code_cell("import math"),
                nbformat.v4.new_markdown_cell("**Exercise 1.** Define `area`, the area of a unit circle."),
                solution, nbformat.v4.new_code_cell(check), nbformat.v4.new_code_cell("print(round(area, 3))")]
    nbformat.write(nb, path)


def test_the_plugin_passes_good_checks_and_fails_each_kind_of_bad_one(tmp_path):
    _exercise_notebook(tmp_path / "good.ipynb", ["area = 3.14", "area = 2 * math.pi"])
    _exercise_notebook(tmp_path / "lenient.ipynb", ["area = 3.14", "area = math.pi + 1e-12"])
    _exercise_notebook(tmp_path / "silent.ipynb", ["area = 3.14", "area = 2 * math.pi"], check="assert area == math.pi")
    _exercise_notebook(tmp_path / "few.ipynb", ["area = 3.14"])
    run = subprocess.run([sys.executable, "-m", "pytest", "-p", "quadlib.teaching.nbval_exercises", "--nbval",
                          "-p", "no:cacheprovider", "-rA", "."],
                         cwd=tmp_path, capture_output=True, text=True, timeout=300)
    outcome = dict((name, verdict) for verdict, name in
                   re.findall(r"^(PASSED|FAILED) (\w+)\.ipynb::Exercise 1 answers", run.stdout, re.MULTILINE))
    assert outcome == {"good": "PASSED", "lenient": "FAILED", "silent": "FAILED", "few": "FAILED"}, run.stdout
    parts = re.split(r"_{3,} (\w+)\.ipynb::Exercise 1 answers _{3,}", run.stdout)
    why = dict(zip(parts[1::2], parts[2::2], strict=True))  # each failure's report
    assert "math.pi + 1e-12" in why["lenient"] and "3.14" not in why["lenient"].split("did not reject")[1], run.stdout
    assert "NameError" in why["silent"] and "list a few" in why["few"], run.stdout
    assert "3 failed, 17 passed" in run.stdout, run.stdout  # every cell, after the exercise too, ran and passed


def test_the_mutation_run_reports_each_answer_tried(tmp_path):
    _exercise_notebook(tmp_path / "lenient.ipynb", ["area = 3.14", "area = math.pi + 1e-12"])
    tried = mutation_run(tmp_path / "lenient.ipynb")
    assert [(m.source, m.rejected, m.blank) for m in tried] == [
        ("# Your answer: define area here.\n", True, True), ("area = 3.14", True, False),
        ("area = math.pi + 1e-12", False, False)]
    assert tried[0].feedback.startswith("AssertionError: answer not set yet") and tried[2].feedback == "passed"
    assert "not the area of a unit circle" in tried[1].feedback
