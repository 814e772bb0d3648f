"""The errata appendix proves itself: every erratum has a proof cell that asserts, and the proofs
run here too, in the unit suite."""

import json
import re
from pathlib import Path

import matplotlib
import pytest

APPENDIX = Path(__file__).resolve().parents[1] / "notebooks" / "90_errata.ipynb"
CELLS = json.loads(APPENDIX.read_text())["cells"]


def _sections() -> dict[str, list[str]]:
    """Erratum id -> the code of the cells between its heading and the next erratum's."""
    sections, current = {}, None
    for cell in CELLS:
        source = "".join(cell["source"])
        if cell["cell_type"] == "markdown":
            for found in re.findall(r"^## (E\d+)\b", source, re.M):
                current = found
                sections[current] = []
        elif current is not None:
            sections[current].append(source)
    return sections


def test_every_erratum_has_a_proof_cell_that_asserts():
    sections = _sections()
    markdown = "".join("".join(c["source"]) for c in CELLS if c["cell_type"] == "markdown")
    listed = set(re.findall(r"^\| (E\d+) \|", markdown, re.M))
    missing = sorted(listed - set(sections))
    assert listed and not missing, f"errata in the table without a section: {missing}"
    lacking = [e for e, cells in sections.items() if not any(re.search(r"^\s*assert ", c, re.M) for c in cells)]
    assert not lacking, f"errata without an asserting proof cell: {lacking}"


def test_the_proofs_hold():
    matplotlib.use("Agg")
    namespace = {}
    code = ["\n".join(line for line in "".join(c["source"]).splitlines() if not line.startswith("%"))
            for c in CELLS if c["cell_type"] == "code"]
    for i, source in enumerate(code):
        try:
            exec(compile(source, f"90_errata code cell {i}", "exec"), namespace)  # noqa: S102
        except AssertionError as err:  # a proof that fails names its cell
            pytest.fail(f"proof in code cell {i} of the errata appendix failed: {err!r}")
