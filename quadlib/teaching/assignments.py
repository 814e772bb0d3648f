"""A chapter as an otter-grader assignment: the master notebook ``otter assign`` turns into the
student edition and the autograder, and the reading of its results.

A chapter keeps the project's own exercise format (:mod:`quadlib.teaching.grading`): a statement,
a solution cell tagged ``solution`` and the check after it. :func:`otter_master` rewrites it in
otter's master format, one question per exercise:

* the solution becomes the question's solution block; the student edition gets an answer cell
  that names what to define;
* the check's guards (``assert "x" in globals(), "answer not set yet: …"``) become the question's
  **public** test: it runs when a student calls ``grader.check("q1")`` and says only whether the
  answer is set — it holds no expected value;
* the rest of the check becomes its **hidden** test, worth the question's points, run only by the
  grader (its ``print`` calls dropped: a grader prints nothing). Its assertion messages are the
  feedback a submission gets;
* an open question (``(Open.)``) becomes a manual question worth its rubric's points, with an
  answer cell; its rubric stays with the instructor.

The chapter's own check cells are thus the instructor's tests, byte for byte (tested), and the
nbval run of each chapter tries every listed wrong answer against them.
"""

from __future__ import annotations

import ast
import copy
import os
import re
from pathlib import Path

from quadlib.teaching.grading import RUBRIC_TAG, SOLUTION_TAG, blank_answer, exercises
from quadlib.validation import as_count

__all__ = ["EXERCISE_POINTS", "GUARD", "build_assignment", "hidden_test", "otter_master", "public_test",
           "question_points", "rubric_points"]

EXERCISE_POINTS = 2
"""Points of a graded exercise (its hidden test); an open question is worth its rubric's points."""

GUARD = re.compile(r'^assert "(\w+)" in globals\(\), "answer not set yet: [^"\n]*"\s*$', re.MULTILINE)
"""A check's guard line: the answer is defined (the student edition's blank answer fails it)."""


def _notebook(nb):
    if not (hasattr(nb, "cells") and isinstance(nb.cells, list)):
        raise TypeError(f"nb: expected a notebook (nbformat.NotebookNode), got {type(nb).__name__}")
    return nb


def public_test(check: str) -> str:
    """The public test of a check: its guard lines, each also refusing otter's placeholder ``...``."""
    if not isinstance(check, str):
        raise TypeError(f"check: expected the source of a check cell, got {type(check).__name__}")
    lines = [m.group(0) for m in GUARD.finditer(check)]
    if not lines:
        raise ValueError("check: expected guard lines 'assert \"name\" in globals(), \"answer not set yet: …\"', "
                         "found none")
    tests = []
    for line, name in zip(lines, GUARD.findall(check), strict=True):
        message = line[line.index('"answer not set yet'):].strip()
        tests.append(f'assert "{name}" in globals() and {name} is not ..., {message}')
    return "\n".join(tests) + "\n"


class _NoPrint(ast.NodeTransformer):
    """Drops ``print(...)`` statements, and gives other bare expressions a target (a doctest would
    print their value and then fail for printing)."""

    def visit_Expr(self, node):
        if isinstance(node.value, ast.Call) and isinstance(node.value.func, ast.Name) and node.value.func.id == "print":
            return ast.Pass()
        if isinstance(node.value, ast.Constant):
            return node
        return ast.Assign(targets=[ast.Name("_", ast.Store())], value=node.value, lineno=node.lineno)


def hidden_test(check: str) -> str:
    """The hidden test of a check: everything but its guard lines, with its ``print`` calls dropped."""
    if not isinstance(check, str):
        raise TypeError(f"check: expected the source of a check cell, got {type(check).__name__}")
    body = GUARD.sub("", check)
    tree = ast.fix_missing_locations(_NoPrint().visit(ast.parse(body)))
    return ast.unparse(tree) + "\n"


def rubric_points(rubric: str) -> int:
    """The points of an open question's rubric: the sum of its ``**N point(s)**`` criteria."""
    if not isinstance(rubric, str):
        raise TypeError(f"rubric: expected the rubric's markdown, got {type(rubric).__name__}")
    points = [int(p) for p in re.findall(r"\*\*(\d+) points?\*\*", rubric)]
    if not points:
        raise ValueError("rubric: expected criteria written '**N point(s)** — …', found none")
    return sum(points)


def question_points(nb) -> list[tuple[str, int, bool]]:
    """``(name, points, manual)`` of every question :func:`otter_master` makes of ``nb``, in order."""
    master = otter_master(nb, "chapter")
    out = []
    for cell in master.cells:
        if cell.cell_type == "raw" and cell.source.startswith("# BEGIN QUESTION"):
            fields = dict(line.split(": ", 1) for line in cell.source.splitlines()[1:])
            out.append((fields["name"], int(fields["points"]), fields.get("manual") == "true"))
    return out


def _raw(source: str):
    import nbformat

    return nbformat.v4.new_raw_cell(source)


def _test_cell(source: str, hidden: bool, points: int):
    import nbformat

    config = f'""" # BEGIN TEST CONFIG\nhidden: {str(hidden).lower()}\npoints: {points}\n""" # END TEST CONFIG\n'
    return nbformat.v4.new_code_cell(config + source)


def otter_master(nb, name: str, points: int = EXERCISE_POINTS):
    """The chapter ``nb`` in otter-grader's master format, as assignment ``name`` (module documentation).

    Parameters
    ----------
    nb : nbformat.NotebookNode
        A chapter with the project's exercises (solution cells tagged ``solution``, each followed by
        its check; open questions followed by a rubric cell tagged ``rubric``).
    name : str
        The assignment's name; the student edition is to be saved as ``name + ".ipynb"``.
    points : int
        Points of each graded exercise.
    """
    nb = copy.deepcopy(_notebook(nb))
    if not isinstance(name, str) or not re.fullmatch(r"[\w.-]+", name):
        raise ValueError(f"name: expected an assignment name of letters, digits, '_', '-' or '.', got {name!r}")
    points = as_count("points", points)
    by_statement = {ex.statement: ex for ex in exercises(nb)}
    config = _raw("# ASSIGNMENT CONFIG\n" + "\n".join([
        f"name: {name}", "init_cell: true", "check_all_cell: false", "export_cell: false", "run_tests: false",
        "solutions_pdf: false", "template_pdf: false", "generate: true", "tests:", "  files: false",
        "  ok_format: true"]) + "\n")
    cells, number, i = [config], 0, 0
    while i < len(nb.cells):
        cell = nb.cells[i]
        if i in by_statement:
            ex = by_statement[i]
            number += 1
            solution, check = nb.cells[ex.answer], nb.cells[ex.check]
            solution.metadata = {}  # no tags, no listed wrong answers, nothing folded: an answer cell to fill in
            body = solution.source.rstrip()
            solution.source = f"{blank_answer(ex)}# BEGIN SOLUTION NO PROMPT\n{body}\n# END SOLUTION\n"
            cells += [_raw(f"# BEGIN QUESTION\nname: q{number}\npoints: {points}"), *nb.cells[i:ex.answer],
                      _raw("# BEGIN SOLUTION"), solution, _raw("# END SOLUTION"), _raw("# BEGIN TESTS"),
                      _test_cell(public_test(check.source), hidden=False, points=0),
                      _test_cell(hidden_test(check.source), hidden=True, points=points),
                      _raw("# END TESTS"), _raw("# END QUESTION")]
            i = ex.check + 1
        elif (cell.cell_type == "markdown" and "(Open.)" in cell.source and i + 1 < len(nb.cells)
              and RUBRIC_TAG in nb.cells[i + 1].metadata.get("tags", [])):
            number += 1
            rubric = nb.cells[i + 1]  # the solution block: otter puts an answer cell in its place
            cells += [_raw(f"# BEGIN QUESTION\nname: q{number}\nmanual: true\npoints: {rubric_points(rubric.source)}"),
                      cell, _raw("# BEGIN SOLUTION"), rubric, _raw("# END SOLUTION"), _raw("# END QUESTION")]
            i += 2
        else:
            cells.append(cell)
            i += 1
    nb.cells = cells
    nb.metadata["kernelspec"] = {"display_name": "Python 3", "language": "python", "name": "python3"}
    nb.metadata.setdefault("language_info", {"name": "python"})
    return nb


def build_assignment(chapter: str | os.PathLike, out_dir: str | os.PathLike) -> list[tuple[str, int, bool]]:
    """Write a chapter's student edition, autograder and solved submission with ``otter assign``.

    ``out_dir/notebooks/NN_name.ipynb`` is the student edition (answer cells, each followed by
    ``grader.check("qN")``; open questions with an answer cell; no solutions, hidden tests or
    rubrics), ``out_dir/autograder/NN_name.zip`` otter's autograder (public and hidden tests) and
    ``out_dir/solved/NN_name.ipynb`` the student edition with the solutions filled in. A chapter
    without exercises is copied as it is. Returns its questions (:func:`question_points`).
    """
    import shutil
    import subprocess
    import sys
    import tempfile

    import nbformat

    chapter, out_dir = Path(chapter), Path(out_dir)
    if not chapter.is_file():
        raise FileNotFoundError(f"chapter: no such notebook: {str(chapter)!r}")
    nb = nbformat.read(chapter, as_version=4)
    questions = question_points(nb)
    name = chapter.stem
    for sub in ("notebooks", "autograder", "solved"):
        (out_dir / sub).mkdir(parents=True, exist_ok=True)
    if not questions:
        shutil.copy(chapter, out_dir / "notebooks" / chapter.name)
        return questions
    with tempfile.TemporaryDirectory() as work:
        master = Path(work) / f"{name}.ipynb"
        nbformat.write(otter_master(nb, name), master)
        run = subprocess.run([sys.executable, "-m", "otter", "assign", "--no-run-tests", "--no-pdfs", str(master),
                              str(Path(work) / "dist")], capture_output=True, text=True)
        if run.returncode != 0:
            raise RuntimeError(f"{chapter.name}: otter assign failed:\n{run.stdout[-2000:]}{run.stderr[-3000:]}")
        student = nbformat.read(Path(work) / "dist" / "student" / f"{name}.ipynb", as_version=4)
        (zip_path,) = (Path(work) / "dist" / "autograder").glob("*.zip")
        shutil.copy(zip_path, out_dir / "autograder" / f"{name}.zip")
    nbformat.write(student, out_dir / "notebooks" / f"{name}.ipynb")
    solutions = [c.source for c in nb.cells if SOLUTION_TAG in c.metadata.get("tags", [])]
    answers = [c for c in student.cells if c.cell_type == "code" and "otter_answer_cell" in c.metadata.get("tags", [])]
    if len(answers) != len(solutions):
        raise RuntimeError(f"{chapter.name}: {len(solutions)} solutions but {len(answers)} answer cells in the "
                           "student edition")
    for cell, source in zip(answers, solutions, strict=True):
        cell.source = source
    nbformat.write(student, out_dir / "solved" / f"{name}.ipynb")
    return questions
