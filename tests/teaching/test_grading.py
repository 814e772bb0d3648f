"""The tools that prove the checks — the nbval plugin that tries each exercise's blank and listed
wrong answers in every chapter's nbval run, and :func:`mutation_run` — pass good checks and catch
each kind of bad one. (The student edition and the grader: ``test_assignments.py``.)"""

import re
import subprocess
import sys

import nbformat

from quadlib.teaching.grading import mutation_run

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
