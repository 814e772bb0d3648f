"""Motion and sensor models, one module per vehicle."""

from . import height, quad1d, quad2d

__all__ = ["height", "quad1d", "quad2d"]
