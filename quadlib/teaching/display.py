"""Show quadlib's own code inside a notebook, so chapters never copy it, and format the numbers that
the chapters' computed prose quotes."""

from __future__ import annotations

import inspect

import numpy as np

from quadlib.validation import as_finite_array

__all__ = ["rounding", "show_source", "span"]


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


def rounding(value, bound: float = 1e-12) -> str:
    """A difference that should be rounding, as prose: ``"< 1e-12"`` when ``|value| < bound``, else
    the value itself (``"3.4e-07"``), which then stands out.

    The last digits of a floating-point difference change from one CPU to the next (vector units,
    summation order), so a chapter that printed ``4.4e-16`` would print ``6.7e-16`` elsewhere. The
    comparison still fails visibly: a difference above ``bound`` prints as a number.
    """
    arr = as_finite_array("value", value)
    if arr.size != 1:
        raise ValueError(f"value: expected one number, got an array of shape {arr.shape}")
    bound = float(as_finite_array("bound", bound))
    if not bound > 0.0:
        raise ValueError(f"bound: expected a positive number, got {bound!r}")
    magnitude = abs(float(arr.reshape(())))
    return f"< {bound:.0e}" if magnitude < bound else f"{magnitude:.1e}"
