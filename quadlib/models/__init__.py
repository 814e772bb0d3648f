"""Motion and sensor models, one module per vehicle."""

from . import height

__all__ = ["height"]
