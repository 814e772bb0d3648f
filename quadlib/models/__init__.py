"""Motion and sensor models, one module per vehicle."""

from . import height, quad1d, quad2d, rangefinder

__all__ = ["height", "quad1d", "quad2d", "rangefinder"]
