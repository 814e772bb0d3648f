"""Show quadlib's own code inside a notebook, so chapters never copy it."""

from __future__ import annotations

import inspect

__all__ = ["show_source"]


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
