"""Graded exercises as a chapter writes them, and the proof that their checks reject wrong answers.

A chapter's exercise is three cells: its statement (markdown, naming each answer in backticks),
the solution (a code cell tagged ``solution``) and the check (the next code cell, which says
"answer not set yet" for a missing answer and otherwise asserts that the answer is right, with a
message that says what is wrong without giving the answer away). An open question is graded by
hand: its statement is followed by a markdown cell tagged ``rubric`` (criteria and points, inside a
``<details>`` element, so Jupyter and the instructor book show it collapsed).

The student edition and the grading are otter-grader's (:mod:`quadlib.teaching.assignments`: the
check's guards become the public test, the rest of it the hidden one; :mod:`~quadlib.teaching.autograde`
runs the autograder). This module proves the checks before any student sees them:

* :func:`mutation_run`: a solution cell lists plausible wrong answers in its metadata
  (``"mutations"``: a guess of the right order, a neighbouring quantity, another filter's figure, a
  unit or sign slip), and each, run in place of the solution, must make the check fail with
  something other than "answer not set yet"; the student edition's blank answer cell
  (:func:`blank_answer`), run there too, must make it say "answer not set yet".
* :func:`try_answers` tries one exercise's answers in a running kernel; the nbval plugin
  :mod:`~quadlib.teaching.nbval_exercises` calls it inside nbval's run of each chapter.
"""

from __future__ import annotations

import ast
import re
from dataclasses import dataclass
from pathlib import Path

from quadlib.validation import as_count, as_instance, as_positive

__all__ = ["ANSWER_TAG", "RUBRIC_TAG", "SOLUTION_TAG", "Exercise", "Mutation", "blank_answer", "exercises",
           "mutation_run", "try_answers"]

SOLUTION_TAG, ANSWER_TAG, RUBRIC_TAG = "solution", "answer", "rubric"
_NAME = re.compile(r"`([A-Za-z_]\w*)[`(]")
_PLACEHOLDER = re.compile(r"\b([A-Za-z_]\w*)\b(?=[^\n]* here\.)")


def _defined(source: str) -> set[str]:
    """The names a cell's top level assigns or defines."""
    names = set()
    for node in ast.parse(source).body:
        if isinstance(node, ast.Assign):
            for target in node.targets:
                names |= {n.id for n in ast.walk(target) if isinstance(n, ast.Name)}
        elif isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            names.add(node.name)
    return names


@dataclass(frozen=True)
class Exercise:
    """One exercise of a notebook: the indices of its ``statement``, ``answer`` (solution or
    student answer) and ``check`` cells, and the ``answers`` it asks for (names)."""

    statement: int
    answer: int
    check: int
    answers: tuple[str, ...]


def _notebook(nb):
    if not (hasattr(nb, "cells") and isinstance(nb.cells, list)):
        raise TypeError(f"nb: expected a notebook (nbformat.NotebookNode), got {type(nb).__name__}")
    return nb


def exercises(nb) -> list[Exercise]:
    """The exercises of notebook ``nb``, in order (module documentation)."""
    cells = _notebook(nb).cells
    out = []
    for i, cell in enumerate(cells):
        tags = cell.get("metadata", {}).get("tags", [])
        if SOLUTION_TAG not in tags and ANSWER_TAG not in tags:
            continue
        j = i - 1
        while j >= 0 and cells[j].cell_type != "markdown":
            j -= 1
        statement = cells[j].source if j >= 0 else ""
        defined = _defined(cell.source) if SOLUTION_TAG in tags else set(_PLACEHOLDER.findall(cell.source))
        answers = tuple(n for n in dict.fromkeys(_NAME.findall(statement)) if n in defined)
        out.append(Exercise(statement=j, answer=i, check=i + 1, answers=answers))
    return out


def blank_answer(ex: Exercise) -> str:
    """The student edition's answer cell of ``ex``: a comment naming what to define."""
    return f"# Your answer: define {', '.join(ex.answers) or 'your answer'} here.\n"


def _submission(path, timeout_s: float):
    """The notebook at ``path`` and a client that runs it in its folder, running on past errors."""
    import nbformat

    from quadlib.teaching.execution import notebook_client  # imports nbclient (2 s): only when grading

    timeout = as_positive("timeout_s", timeout_s)
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"path: expected a notebook file, got {str(path)!r}, which does not exist")
    nb = nbformat.read(path, as_version=4)
    return nb, notebook_client(nb, path.parent, timeout, allow_errors=True)


def _error(cell) -> tuple[str, str] | None:
    """The name and message of the first error a cell's outputs hold, or None."""
    for out in cell.get("outputs", []):
        if out.get("output_type") == "error":
            return out.get("ename", ""), out.get("evalue", "")
    return None


@dataclass(frozen=True)
class Mutation:
    """One answer tried by :func:`mutation_run`: the exercise's ``number``, the answer's ``source``,
    whether the check ``rejected`` it as it should, and the check's ``feedback``. A wrong answer is
    rejected by an ``AssertionError`` that is not "answer not set yet"; the ``blank`` answer (the
    student edition's empty cell) by one that is."""

    number: int
    source: str
    rejected: bool
    feedback: str
    blank: bool = False


def try_answers(nb, ex: Exercise, number: int, execute) -> list[Mutation]:
    """Try exercise ``ex`` (number ``number``) of ``nb`` where its solution would run: the student
    edition's blank answer, then each of the solution's ``mutations``, each followed by the check.
    ``execute(source)`` runs code in the kernel and returns the name and message of the error it
    raised, or None. The kernel keeps whatever the last answer tried defined."""
    nb = _notebook(nb)
    as_instance("ex", ex, Exercise)
    number = as_count("number", number)
    if not callable(execute):
        raise TypeError(f"execute: expected a function of the source that returns an error or None, got "
                        f"{type(execute).__name__}")
    results = []
    for k, source in enumerate([blank_answer(ex), *nb.cells[ex.answer].metadata.get("mutations", [])]):
        blank = k == 0
        answer_error = execute(source)
        error = answer_error or execute(nb.cells[ex.check].source)
        not_set = error is not None and error[1].startswith("answer not set yet")
        rejected = error is not None and error[0] == "AssertionError" and not_set == blank
        results.append(Mutation(number, source, rejected, "passed" if error is None else ": ".join(error), blank))
    return results


def mutation_run(path, timeout_s: float = 600.0) -> list[Mutation]:
    """Execute the solution edition at ``path`` in one kernel; before each solution, try its blank
    answer and each of its ``mutations`` (:func:`try_answers`), recording whether the check rejected
    each as it should (:class:`Mutation`). The solution and its check then run as usual, and must
    pass. (``make test`` does the same inside nbval's run of each chapter: the root ``conftest.py``.)

    The blank runs where every cell before it has run, solutions included: the kernel holds at
    least the names the student edition's would, so a check that says "answer not set yet" here
    says it there too."""
    import nbformat

    nb, client = _submission(path, timeout_s)
    by_answer = {ex.answer: (number, ex) for number, ex in enumerate(exercises(nb), start=1)}

    def execute(source):
        cell = nbformat.v4.new_code_cell(source)
        client.execute_cell(cell, index)
        return _error(cell)

    results = []
    with client.setup_kernel():
        for index, cell in enumerate(nb.cells):
            if index in by_answer:
                number, ex = by_answer[index]
                results += try_answers(nb, ex, number, execute)
            if cell.cell_type == "code":
                client.execute_cell(cell, index)
                error = _error(cell)
                if error is not None and "raises-exception" not in cell.metadata.get("tags", []):
                    raise RuntimeError(f"{Path(path).name}, cell {index}: the solution edition failed: "
                                       f"{': '.join(error)}")
    return results
