"""Grading submitted chapters with the instructor's tests (otter-grader), and what it reports.

:func:`grade_folder` grades every ``*.ipynb`` below a folder as a submission of the chapter its file
name (or, failing that, its otter metadata) names, with that chapter's autograder
(``NN_name.zip``, written by :func:`quadlib.teaching.assignments.build_assignment`), never with the
submission's own cells:

* each submission runs in a process of its own (:mod:`quadlib.teaching.otter_run`), in a folder
  holding only the autograder and the submission, with a grading copy of quadlib, the data and the
  stored benchmark tables (``_build/grading_env``): the chapters' notebooks, and with them the
  solutions, are not where the kernel looks;
* a cell that runs over ``cell_timeout_s`` is interrupted and grading goes on; a submission that
  runs over ``submission_timeout_s`` is stopped (its whole process tree), and one whose kernel dies
  is recorded as such — both get 0 on every autograded question, and the next submission is graded;
* ``scores.csv`` gets one row per submission and question, written as each submission finishes:
  points earned and possible, the tests' feedback (the assertion messages of the hidden tests, never
  their code), a note on the submission (a cell stopped, a timeout, a dead kernel), and for the open
  questions, which are graded by hand, no points yet and the student's answer.

What a tampering student can still do is in the README: code in a submission runs with the
grader's permissions, so it can, for instance, replace ``numpy.isclose`` before the tests run.
"""

from __future__ import annotations

import csv
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

from quadlib.data.paths import PROJECT_ROOT
from quadlib.teaching.otter_run import TIMEOUT_MARK
from quadlib.validation import as_count

__all__ = ["FIELDS", "QuestionResult", "feedback", "grade_folder", "grade_submission", "grading_env", "read_results"]

_ERROR = re.compile(r"^\s*(\w*(?:Error|Exception|Interrupt))(?::\s*(.*))?$")


def feedback(output: str) -> str:
    """What a question's failed tests said, from otter's report of them: the message of the first
    exception each failed test case raised (an assertion's message is the check's feedback), without
    the tests' code, one per line; only "answer not set yet" when that is what a test said; "passed"
    if none failed."""
    if not isinstance(output, str):
        raise TypeError(f"output: expected otter's test output (str), got {type(output).__name__}")
    messages = []
    for case in re.split(r"\n\s*\w+ - \d+ result:", output):
        if "Test case failed" not in case:
            continue
        found = [m for m in (_ERROR.match(line) for line in case.splitlines()) if m]
        if found:
            name, message = found[0].groups()
            text = message if name == "AssertionError" and message else f"{name}: {message or ''}".rstrip(": ")
        else:
            text = "failed"
        if text not in messages:
            messages.append(text)
    unset = [m for m in messages if m.startswith("answer not set yet")]
    return "\n".join(unset or messages) or "passed"


@dataclass(frozen=True)
class QuestionResult:
    """One question of one graded submission: its ``name`` (``q1`` …), the ``points`` earned (None
    for a question graded by hand), the points ``possible`` and the ``feedback``."""

    name: str
    points: float | None
    possible: float
    feedback: str


def read_results(results: str | os.PathLike, questions: list[tuple[str, int, bool]]) -> list[QuestionResult]:
    """The results of ``otter run`` (its ``results.json``) for each of ``questions``
    (:func:`question_points`); a manual question is left for the instructor."""
    path = Path(results)
    tests = {t["name"]: t for t in json.loads(path.read_text())["tests"]}
    out = []
    for name, possible, manual in questions:
        if manual:
            out.append(QuestionResult(name, None, possible, "graded by hand with the rubric"))
        elif name in tests:
            t = tests[name]
            score = float(t.get("score") or 0.0)
            out.append(QuestionResult(name, score, float(possible), feedback(t.get("output", ""))))
        else:
            out.append(QuestionResult(name, 0.0, float(possible), "not graded: the grader found no result"))
    return out


FIELDS = ["submission", "chapter", "question", "points", "possible", "feedback", "note", "answer"]


def grading_env(target: Path) -> Path:
    """A copy of quadlib (with its compiled caches), the data and the stored benchmark tables, and
    nothing else of the project: the chapters' kernels import quadlib from here."""
    if target.exists():
        shutil.rmtree(target)  # made anew for every grading, from the quadlib of today
    shutil.copytree(PROJECT_ROOT / "quadlib", target / "quadlib", ignore=shutil.ignore_patterns("*.pyc"))
    shutil.copytree(PROJECT_ROOT / "data", target / "data")
    shutil.copytree(PROJECT_ROOT / "benchmarks" / "results", target / "benchmarks" / "results")
    return target


def _questions(autograder: Path) -> list[tuple[str, int, bool]]:
    """The chapter's questions from ``points.csv`` beside the autograders."""
    with (autograder.parent.parent / "points.csv").open(newline="") as f:
        return [(r["question"], int(r["points"]), r["graded"] == "by hand") for r in csv.DictReader(f)
                if r["chapter"] == autograder.stem]


def _chapter(path: Path, autograders: Path) -> Path | None:
    for name in (path.stem, _metadata_name(path)):
        if name and (autograders / f"{name}.zip").is_file():
            return autograders / f"{name}.zip"
    return None


def _metadata_name(path: Path) -> str | None:
    try:
        return json.loads(path.read_text()).get("metadata", {}).get("otter", {}).get("assignment_name")
    except (OSError, ValueError, AttributeError):
        return None


def _manual_answers(path: Path) -> dict[str, str]:
    """The text of each answer cell of a question graded by hand (otter's answer cells after an
    open question), by question name."""
    import nbformat

    try:
        nb = nbformat.read(path, as_version=4)
    except Exception:  # an unreadable notebook: its grading will say so
        return {}
    answers, number = {}, 0
    for cell in nb.cells:
        if cell.cell_type == "code" and 'grader.check("q' in cell.source:
            number = max(number, int(cell.source.split('grader.check("q')[1].split('"')[0]))
        elif cell.cell_type == "markdown" and "otter_answer_cell" in cell.metadata.get("tags", []):
            number += 1
            answers[f"q{number}"] = cell.source.strip()
    return answers


def _ungraded(questions, note: str) -> list[QuestionResult]:
    """0 points on every autograded question of a submission that could not be graded."""
    return [QuestionResult(q, None if manual else 0.0, float(p), "graded by hand with the rubric" if manual else note)
            for q, p, manual in questions]


def _kill_tree(process: subprocess.Popen) -> None:
    """Kill a grading process and everything it started (the notebook's kernel)."""
    import psutil

    try:
        children = psutil.Process(process.pid).children(recursive=True)
    except psutil.NoSuchProcess:
        children = []
    for p in [*children, psutil.Process(process.pid)] if process.poll() is None else children:
        try:
            p.kill()
        except psutil.NoSuchProcess:
            pass
    process.wait()


def grade_submission(path: Path, autograder: Path, env_dir: Path, cell_timeout_s: int,
                     submission_timeout_s: int) -> tuple[list[QuestionResult], str]:
    """Grade one submission in a process and a folder of its own: its results and a note."""
    questions = _questions(autograder)
    with tempfile.TemporaryDirectory() as work:
        out = Path(work) / "results"
        out.mkdir()
        submission = Path(work) / f"{autograder.stem}.ipynb"
        shutil.copy(path, submission)
        env = dict(os.environ, PYTHONPATH=str(env_dir), QUADLIB_PROGRESS="off")
        with (Path(work) / "log.txt").open("w") as log:
            process = subprocess.Popen([sys.executable, "-m", "quadlib.teaching.otter_run", str(cell_timeout_s),
                                        str(autograder.resolve()), str(submission), str(out)], cwd=work, env=env,
                                       stdout=log, stderr=subprocess.STDOUT)
            try:
                process.wait(submission_timeout_s)
            except subprocess.TimeoutExpired:
                _kill_tree(process)
                note = f"not graded: the submission ran over {submission_timeout_s} s"
                return _ungraded(questions, note), note
        text = (Path(work) / "log.txt").read_text(errors="replace")
        if not (out / "results.json").is_file():
            reason = "its kernel died (out of memory, or the process was killed)" if "DeadKernelError" in text \
                else f"the grader failed: {text.strip().splitlines()[-1] if text.strip() else 'no output'}"
            note = f"not graded: {reason}"
            return _ungraded(questions, note), note
        note = f"a cell ran over {cell_timeout_s} s and was stopped" if TIMEOUT_MARK in text else ""
        return read_results(out / "results.json", questions), note


def grade_folder(folder: str | os.PathLike, autograders: str | os.PathLike, cell_timeout_s: int = 120,
                 submission_timeout_s: int = 1200, log=None) -> Path:
    """Grade every ``*.ipynb`` below ``folder`` (module documentation) into ``folder/scores.csv``,
    a row per submission and question written as each submission finishes; returns its path.
    ``log(line)``, if given, hears one line per submission graded."""
    log = log or (lambda line: None)
    folder, autograders = Path(folder), Path(autograders)
    cell_timeout_s = as_count("cell_timeout_s", cell_timeout_s)
    submission_timeout_s = as_count("submission_timeout_s", submission_timeout_s)
    submissions = sorted(p for p in folder.rglob("*.ipynb") if ".ipynb_checkpoints" not in p.parts)
    if not submissions:
        raise FileNotFoundError(f"folder: expected submitted notebooks below {str(folder)!r}, found none")
    if not autograders.is_dir():
        raise FileNotFoundError(f"autograders: no folder {str(autograders)!r}: run 'make student' first")
    env_dir = grading_env(PROJECT_ROOT / "_build" / "grading_env")
    scores = folder / "scores.csv"
    with scores.open("w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=FIELDS)
        writer.writeheader()
        for path in submissions:
            name = str(path.relative_to(folder))
            autograder = _chapter(path, autograders)
            if autograder is None:
                writer.writerow({"submission": name, "note": "not graded: no autograder for this chapter's name"})
                f.flush()
                log(f"{name}: no autograder for it")
                continue
            results, note = grade_submission(path, autograder, env_dir, cell_timeout_s, submission_timeout_s)
            answers = _manual_answers(path)
            for r in results:
                writer.writerow({"submission": name, "chapter": autograder.stem, "question": r.name,
                                 "points": "" if r.points is None else f"{r.points:g}", "possible": f"{r.possible:g}",
                                 "feedback": r.feedback, "note": note, "answer": answers.get(r.name, "")
                                 if r.points is None else ""})
            f.flush()
            earned = sum(r.points or 0.0 for r in results)
            auto = sum(r.possible for r in results if r.points is not None)
            log(f"{name}: {earned:g} of {auto:g} autograded points{'; ' + note if note else ''}")
    return scores


