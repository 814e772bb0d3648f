"""Show quadlib's own code inside a notebook, so chapters never copy it, and format the numbers that
the chapters' computed prose quotes."""

from __future__ import annotations

import inspect

import numpy as np

from quadlib.validation import as_finite_array

__all__ = ["show_source", "span"]


def show_source(obj):
    """Display the source of a quadlib function or class as a highlighted code block.

    Returns an ``IPython.display.Markdown`` object (rendered by Jupyter and by the book).
    """
    from IPython.display import Markdown

    try:
        source = inspect.getsource(obj)
    except (TypeError, OSError) as err:
        raise TypeError(f"obj: expected a function or class defined in Python source, got {obj!r}") from err
    module = getattr(obj, "__module__", "?")
    return Markdown(f"`{module}.{obj.__qualname__}`\n\n```python\n{source}```")


def span(values, spec: str = ".1f") -> str:
    """The range of ``values`` as prose: ``"low–high"`` formatted with ``spec``, or one number when
    both ends print the same (``span([2.86, 2.88])`` is ``"2.9"``, not ``"2.9–2.9"``).

    Chapters build their result sentences from computed values (``Markdown(f"...")``), so the
    numbers in the prose are the numbers of the run; this keeps those sentences readable.
    """
    arr = as_finite_array("values", values)
    if arr.size == 0:
        raise ValueError("values: expected at least one number, got an empty sequence")
    if not isinstance(spec, str):
        raise TypeError(f"spec: expected a format specification such as '.1f', got {spec!r}")
    try:
        low, high = format(float(np.min(arr)), spec), format(float(np.max(arr)), spec)
    except ValueError as err:
        raise ValueError(f"spec: expected a float format specification such as '.1f', got {spec!r}") from err
    return low if low == high else f"{low}–{high}"
