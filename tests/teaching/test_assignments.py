"""The chapters as otter-grader assignments, and the grader: every check becomes a public test that
says only whether the answer is set and a hidden test that holds the value; the student edition holds
no solution, check or rubric; a blank submission scores 0, a perfect one full marks, each listed wrong
answer 0 on its question, and a submission that loops forever, kills its kernel or rewrites its own
checks is recorded and graded by the instructor's tests while grading goes on."""

import ast
import copy
import csv
import re
from pathlib import Path

import nbformat
import pytest

from quadlib.teaching.assignments import (
    GUARD,
    build_assignment,
    hidden_test,
    otter_master,
    public_test,
    question_points,
    rubric_points,
)
from quadlib.teaching.autograde import feedback, grade_folder
from quadlib.teaching.grading import RUBRIC_TAG, SOLUTION_TAG, exercises

NOTEBOOKS = sorted((Path(__file__).resolve().parents[2] / "notebooks").glob("[0-9][0-9]_*.ipynb"))
CHAPTERS = [p for p in NOTEBOOKS if exercises(nbformat.read(p, as_version=4))]

CHECK = '''assert "gain" in globals(), "answer not set yet: store your answer in gain"
expected = 4.0 / (4.0 + 2.0)
print(f"K = {gain:.3f}")
assert abs(gain - expected) < 1e-9, "not the gain"
'''


def test_a_check_splits_into_a_public_and_a_hidden_test():
    public = public_test(CHECK)
    assert public == ('assert "gain" in globals() and gain is not ..., '
                      '"answer not set yet: store your answer in gain"\n')
    hidden = hidden_test(CHECK)
    assert "answer not set yet" not in hidden and "print" not in hidden and "not the gain" in hidden
    env = {"gain": 4.0 / 6.0}
    exec(hidden, env)  # noqa: S102 - the hidden test passes the right answer
    with pytest.raises(AssertionError, match="not the gain"):
        exec(hidden, {"gain": 0.8})  # noqa: S102
    with pytest.raises(AssertionError, match="answer not set yet"):
        exec(public, {"gain": ...})  # noqa: S102 - otter's blank answer
    with pytest.raises(ValueError, match="check: expected guard lines"):
        public_test("assert x == 1")


def test_rubric_points_and_feedback_without_the_tests_code():
    assert rubric_points("- **1 point** — a\n- **2 points** — b\n- **1 point** — c") == 4
    with pytest.raises(ValueError, match="rubric: expected criteria"):
        rubric_points("no points here")
    report = """q1 results:
    q1 - 1 result:
        ❌ Test case failed
        Trying:
            assert abs(gain - 2 / 3) < 1e-9, 'not the gain'
        Exception raised:
            AssertionError: not the gain
    q1 - 2 result:
        ✅ Test case passed"""
    assert feedback(report) == "not the gain" and "2 / 3" not in feedback(report)
    assert feedback("q1 results: All test cases passed!") == "passed"


@pytest.mark.parametrize("path", CHAPTERS, ids=lambda p: p.stem)
def test_every_chapter_becomes_a_master_whose_tests_are_its_checks(path):
    nb = nbformat.read(path, as_version=4)
    master = otter_master(nb, path.stem)
    found, questions = exercises(nb), question_points(nb)
    opened = sum("(Open.)" in c.source for c in nb.cells if c.cell_type == "markdown")
    assert len(questions) == len(found) + opened and sum(manual for *_, manual in questions) == opened
    tests = [c.source for c in master.cells if c.cell_type == "code" and "BEGIN TEST CONFIG" in c.source]
    for ex, (public, hidden) in zip(found, zip(tests[::2], tests[1::2], strict=True), strict=True):
        check = nb.cells[ex.check].source
        assert "hidden: false" in public and "hidden: true" in hidden
        # the hidden test is the chapter's check without its guards and prints: the checks nbval proves
        assert ast.dump(ast.parse(hidden.split("# END TEST CONFIG\n", 1)[1])) == ast.dump(ast.parse(hidden_test(check)))
        public_lines = public.split("# END TEST CONFIG\n", 1)[1].strip().splitlines()
        guard = r'assert "(\w+)" in globals\(\) and \1 is not \.\.\., "answer not set yet: [^"]*"'
        assert len(public_lines) == len(GUARD.findall(check))
        assert all(re.fullmatch(guard, ln) for ln in public_lines)
        for line in (ln for ln in check.splitlines() if ln.startswith("assert ") and "answer not set yet" not in ln):
            assert line.split(",")[0] not in public, "a public test holds a hidden assertion"
    # what the student edition keeps: everything outside the question blocks, which hold every
    # solution, check and rubric
    inside, depth = set(), 0
    for i, cell in enumerate(master.cells):
        if cell.cell_type == "raw" and cell.source.startswith(("# BEGIN SOLUTION", "# BEGIN TESTS")):
            depth += 1
        if depth:
            inside.add(i)
        if cell.cell_type == "raw" and cell.source.startswith(("# END SOLUTION", "# END TESTS")):
            depth -= 1
    kept = [c for i, c in enumerate(master.cells) if i not in inside]
    assert not any(SOLUTION_TAG in c.metadata.get("tags", []) or RUBRIC_TAG in c.metadata.get("tags", [])
                   for c in kept)
    assert not any(nb.cells[ex.check].source in c.source for ex in found for c in kept)


@pytest.fixture(scope="module")
def assignment(tmp_path_factory):
    """Chapter 1 built by otter assign: its student edition, autograder and solved submission."""
    out = tmp_path_factory.mktemp("student")
    chapter = next(p for p in NOTEBOOKS if p.name == "01_averaging.ipynb")
    questions = build_assignment(chapter, out)
    with (out / "points.csv").open("w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(["chapter", "question", "points", "graded"])
        writer.writerows((chapter.stem, q, p, "by hand" if m else "autograded") for q, p, m in questions)
    return out, nbformat.read(chapter, as_version=4), questions


def test_the_student_edition_shows_no_solution_no_expected_value_and_no_rubric(assignment):
    out, chapter, _ = assignment
    student = nbformat.read(out / "notebooks" / "01_averaging.ipynb", as_version=4)
    text = "\n".join(c.source for c in student.cells)
    for ex in exercises(chapter):
        assert chapter.cells[ex.answer].source not in text, "a solution survived"
        assert chapter.cells[ex.check].source not in text, "a check survived"
    assert "Rubric (for instructors" not in text and text.count('grader.check("q') == 3
    assert "Solution hidden" not in text and "mutations" not in str([c.metadata for c in student.cells])
    hidden = str(student.metadata)  # the public tests travel in the metadata: nothing of the hidden ones
    assert "'hidden': True" not in hidden and "rtol" not in hidden


def _submissions(out, chapter, folder):
    """Every kind of submission the grader must survive, in ``folder``."""
    blank = nbformat.read(out / "notebooks" / "01_averaging.ipynb", as_version=4)
    solved = nbformat.read(out / "solved" / "01_averaging.ipynb", as_version=4)
    answers = [i for i, c in enumerate(blank.cells) if "otter_answer_cell" in c.metadata.get("tags", [])
               and c.cell_type == "code"]
    mutations = [chapter.cells[ex.answer].metadata["mutations"] for ex in exercises(chapter)]

    def write(name, nb):
        (folder / name).mkdir(parents=True)
        nbformat.write(nb, folder / name / "01_averaging.ipynb")

    write("blank", blank)
    write("solved", solved)
    for k in range(max(map(len, mutations))):  # the k-th listed wrong answer of every exercise at once
        wrong = copy.deepcopy(solved)
        for i, listed in zip(answers, mutations, strict=True):
            if k < len(listed):
                wrong.cells[i].source = listed[k]
        write(f"wrong{k}", wrong)
    for name, source in (("loops", "while True:\n    pass"), ("dies", "import os\nos.kill(os.getpid(), 9)")):
        bad = copy.deepcopy(solved)
        bad.cells[answers[1]].source = source
        write(name, bad)
    tampered = copy.deepcopy(blank)  # wrong answers, its checks printing "ok", its tags gone
    for i in answers:
        tampered.cells[i].source = "alpha_ex, lag_ex = 0.5, 1.0\nmy_recursive_mean = lambda z: z\nsigma_085 = 0.3"
        tampered.cells[i + 1].source = 'print("ok")'
    for cell in tampered.cells:
        cell.metadata.pop("tags", None)
    write("tampered", tampered)
    return mutations


def test_the_grader_scores_every_kind_of_submission_and_survives_the_bad_ones(assignment, tmp_path):
    out, chapter, questions = assignment
    mutations = _submissions(out, chapter, tmp_path)
    scores = grade_folder(tmp_path, out / "autograder", cell_timeout_s=15, submission_timeout_s=300)
    with scores.open(newline="") as f:
        rows = list(csv.DictReader(f))
    by = {}
    for r in rows:
        by.setdefault(r["submission"].split("/")[0], {})[r["question"]] = r
    auto = [q for q, _, manual in questions if not manual]
    manual = [q for q, _, m in questions if m]
    assert set(by) == {"blank", "solved", "loops", "dies", "tampered"} | {f"wrong{k}" for k in range(4)} & set(by)
    assert all(by["solved"][q]["points"] == by["solved"][q]["possible"] == "2" for q in auto)
    assert all(by["blank"][q]["points"] == "0" and by["blank"][q]["feedback"].startswith("answer not set yet")
               for q in auto)
    for k in range(max(map(len, mutations))):
        for q, listed in zip(auto, mutations, strict=True):
            if k < len(listed):
                row = by[f"wrong{k}"][q]
                assert row["points"] == "0" and row["feedback"] not in ("passed", ""), (k, q, row)
    assert by["loops"]["q2"]["points"] == "0" and "ran over 15 s" in by["loops"]["q2"]["note"]
    assert by["loops"]["q1"]["points"] == by["loops"]["q3"]["points"] == "2"  # graded past the loop
    assert all(by["dies"][q]["points"] == "0" and "kernel died" in by["dies"][q]["note"] for q in auto)
    assert all(by["tampered"][q]["points"] == "0" for q in auto)  # the instructor's tests, not its "ok"
    assert all(by[s][q]["points"] == "" and by[s][q]["possible"] == "4" for s in by for q in manual)
    assert re.search(r"Type your answer here", by["blank"][manual[0]]["answer"])
