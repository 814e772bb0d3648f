"""The chapters' graded exercises keep their shape: each hidden solution (a cell tagged
``solution``) is followed by a check that first says "answer not set yet" for every answer the
exercise asks for (a name in backticks in its statement that the solution defines), so a student
edition with the solutions removed fails with that message rather than a NameError, and that then
asserts something about the answer."""

import ast
import json
import re
from pathlib import Path

import pytest

NOTEBOOKS = sorted((Path(__file__).resolve().parents[1] / "notebooks").glob("[0-9][0-9]_*.ipynb"))


def _exercises(path: Path):
    cells = json.loads(path.read_text())["cells"]
    for i, cell in enumerate(cells):
        if "solution" not in cell.get("metadata", {}).get("tags", []):
            continue
        source = "".join(cell["source"])
        defined = set()
        for node in ast.parse(source).body:
            if isinstance(node, ast.Assign):
                for target in node.targets:
                    defined |= {n.id for n in ast.walk(target) if isinstance(n, ast.Name)}
            elif isinstance(node, ast.FunctionDef):
                defined.add(node.name)
        j = i - 1
        while cells[j]["cell_type"] != "markdown":
            j -= 1
        statement = "".join(cells[j]["source"])
        asked = [n for n in dict.fromkeys(re.findall(r"`([A-Za-z_]\w*)[`(]", statement)) if n in defined]
        yield i, asked, "".join(cells[i + 1]["source"]), cells[i + 1]["cell_type"]


CASES = [(p.name, i, asked, check, kind) for p in NOTEBOOKS for i, asked, check, kind in _exercises(p)]


def test_every_chapter_from_01_has_an_exercise():
    chapters = {p.name for p in NOTEBOOKS if not p.name.startswith(("00", "9"))}
    assert chapters <= {name for name, *_ in CASES}, sorted(chapters - {name for name, *_ in CASES})


@pytest.mark.parametrize(("name", "cell", "asked", "check", "kind"), CASES, ids=[f"{c[0]}:{c[1]}" for c in CASES])
def test_a_solution_is_followed_by_a_guarded_check(name, cell, asked, check, kind):
    assert kind == "code", "the cell after a solution must be its check"
    assert asked, "the statement names no answer (in backticks) that the solution defines"
    for answer in asked:
        guard = re.search(rf'assert "{answer}" in globals\(\), "answer not set yet: [^"]*{answer}', check)
        assert guard, f"no 'answer not set yet' guard for {answer}"
    body = re.sub(r'(?m)^.*answer not set yet.*$', "", check)
    assert re.search(r"(?m)^\s*assert ", body), "the check asserts nothing about the answer"
