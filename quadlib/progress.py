"""Progress bars for the chapters' long loops: drawn in Jupyter, silent in the tests and the book.

A bar is drawn unless the environment variable ``QUADLIB_PROGRESS`` is ``off``. The test suite
(``conftest.py``), the book's build (``book/conf.py``) and the scripts that store or grade
notebooks set it before any kernel starts, and a kernel inherits it: the stored outputs then
hold no bar, and stay the same on every run.
"""

from __future__ import annotations

import os
from collections.abc import Iterable

from tqdm.auto import tqdm

from quadlib.validation import as_count, as_optional

__all__ = ["ENV_VAR", "progress", "progress_enabled", "switch_off"]

ENV_VAR = "QUADLIB_PROGRESS"


def progress_enabled() -> bool:
    """Whether :func:`progress` draws bars (``QUADLIB_PROGRESS`` is not ``off``)."""
    return os.environ.get(ENV_VAR, "on").strip().lower() != "off"


def switch_off() -> None:
    """Switch bars off for this process and every kernel it starts from now on."""
    os.environ[ENV_VAR] = "off"


def progress(iterable: Iterable, label: str, total: int | None = None) -> Iterable:
    """``iterable`` with a progress bar named ``label``, removed when the loop ends.

    ``total`` is the number of items, for an iterable without a length (a generator).
    When bars are off (:func:`progress_enabled`) the iterable itself is returned.
    """
    if not isinstance(label, str) or not label:
        raise TypeError(f"label: expected a non-empty str, got {label!r}")
    total = as_optional(as_count, "total", total, low=0)
    if not isinstance(iterable, Iterable):
        raise TypeError(f"iterable: expected an iterable, got {type(iterable).__name__}")
    if not progress_enabled():
        return iterable
    return tqdm(iterable, desc=label, total=total, leave=False)
