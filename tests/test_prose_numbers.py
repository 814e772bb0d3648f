"""Prose that cannot drift: a chapter's markdown quotes no result.

Every result a chapter states in words is printed by a computed cell (``Markdown(f"...")``, its input
hidden in the book), so the sentence changes when the computation does and nbval compares it. This
test flags a number in a markdown cell — a decimal or a percentage, outside mathematics, code and
citations — that equals, to the digits it shows, a number in the chapter's stored outputs, unless
the chapter's code sets that value (a stated input: a noise σ, a rate, a gate probability).
"""

from __future__ import annotations

import re
from decimal import Decimal
from pathlib import Path

import nbformat
import pytest

NOTEBOOKS = sorted((Path(__file__).resolve().parent.parent / "notebooks").glob("[0-9]*.ipynb"))

NUMBER = re.compile(r"(?<![\w.§])(\d+\.\d+|\d+(?=\s?%))(\s?%)?")
REFERENCE = r"\(?\d+(?:\.\d+)*\)?"
CITATION = re.compile(rf"(?:eqs?\.|equations?|§|figs?\.|figure|table|algorithm|section|chapter|ch\.)\s*{REFERENCE}"
                      rf"(?:\s*(?:–|-|,|and)\s*{REFERENCE})*", re.IGNORECASE)
LITERAL = re.compile(r"(?<![\w.])\d+\.?\d*(?:e-?\d+)?")


def prose(markdown: str) -> str:
    """A markdown cell without mathematics, code, link targets, headings and citations."""
    text = re.sub(r"\$\$.*?\$\$|\$[^$\n]*\$|`[^`]*`|\]\([^)]*\)|^#+ .*$", " ", markdown, flags=re.S | re.M)
    return CITATION.sub(" ", text)


def output_numbers(nb) -> list[Decimal]:
    """Every number printed by the chapter's cells, quadlib's listed source code excepted."""
    texts = []
    for cell in nb.cells:
        for out in cell.get("outputs", []) if cell.cell_type == "code" else []:
            data = out.get("data", {})
            text = out.get("text") or data.get("text/markdown") or data.get("text/plain") or ""
            if not text.startswith("`quadlib."):
                texts.append(text)
    return [Decimal(n) for n in re.findall(r"\d+\.?\d*", "\n".join(texts))]


def code_values(nb) -> set[Decimal]:
    values = set()
    for cell in nb.cells:
        if cell.cell_type == "code":
            values.update(Decimal(str(float(n))).normalize() for n in LITERAL.findall(cell.source))
    return values


def copied_numbers(nb) -> list[str]:
    """Markdown numbers equal, at their printed precision, to a printed result and not set by the code."""
    printed, inputs = output_numbers(nb), code_values(nb)
    found = []
    for i, cell in enumerate(nb.cells):
        if cell.cell_type != "markdown":
            continue
        for match in NUMBER.finditer(prose(cell.source)):
            value, percent = Decimal(match.group(1)), bool(match.group(2))
            stated = {value.normalize(), (value / 100).normalize()} if percent else {value.normalize()}
            if stated & inputs:
                continue
            quantum = Decimal(1).scaleb(value.as_tuple().exponent)
            candidates = printed + ([p * 100 for p in printed if p <= 1] if percent else [])
            if any(p.quantize(quantum) == value for p in candidates):
                found.append(f"cell {i}: {match.group(0)!r}")
    return found


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.stem)
def test_markdown_quotes_no_printed_result(path):
    found = copied_numbers(nbformat.read(path, as_version=4))
    assert not found, (f"{path.name}: these markdown numbers repeat printed results; print them from a computed "
                       f"cell (Markdown(f'...')) instead: {', '.join(found)}")


def test_the_check_finds_a_copied_result():
    nb = nbformat.v4.new_notebook()
    nb.cells = [nbformat.v4.new_code_cell("sigma = 0.2\nprint(rmse)", outputs=[
                    nbformat.v4.new_output("stream", text="RMSE 4.79 cm, caught 61%\n")]),
                nbformat.v4.new_markdown_cell("Noise σ 0.2 m (eq. 4.79); the RMSE is 4.8 cm and the gate "
                                              "catches 61 % of them, $x = 4.79$.")]
    assert copied_numbers(nb) == ["cell 1: '4.8'", "cell 1: '61 %'"]
