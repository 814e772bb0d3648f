"""Chapters run from anywhere: `make book` executes copies in book/chapters/, so a path relative to
notebooks/ would miss its file there (chapter 16 once read ../benchmarks/results that way)."""

import json
import re
from pathlib import Path

NOTEBOOKS = sorted((Path(__file__).resolve().parents[1] / "notebooks").glob("*.ipynb"))


def test_no_chapter_opens_a_path_relative_to_its_own_folder():
    relative = re.compile(r"""["']\.\.?/""")
    offenders = [f"{nb.name}: {line.strip()}" for nb in NOTEBOOKS
                 for cell in json.loads(nb.read_text())["cells"] if cell["cell_type"] == "code"
                 for line in "".join(cell["source"]).splitlines() if relative.search(line)]
    assert NOTEBOOKS and not offenders, offenders
