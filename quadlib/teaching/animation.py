"""Animations for the book: the 2D quadrotor and its range beam, as deterministic HTML.

``matplotlib``'s ``Animation.to_jshtml`` names its HTML elements with a random id, so the same
animation renders to different HTML on every run, and it styles its buttons with icons loaded
from a CDN, which an offline book cannot reach. :func:`animation_html` replaces the id by a fixed
one and the icons by plain characters; with the frames drawn at a fixed size and dpi the output
is then the same on every run, and needs no network.
"""

from __future__ import annotations

import re

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.animation import FuncAnimation

from quadlib.validation import as_count, as_finite_array, as_finite_number, as_positive, as_times

__all__ = ["animate_quad2d", "animation_html", "quad2d_geometry"]

_HTML_ID = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
_RANDOM_ID = re.compile(r"_anim_img([0-9a-f]{32})")
_ICON_CSS = re.compile(r'<link rel="stylesheet"\s*href="https?://[^"]*font-awesome[^"]*">\s*')
_ICONS = {"fa fa-minus": "−", "fa fa-plus": "+", "fa fa-fast-backward": "⏮", "fa fa-fast-forward": "⏭",
          "fa fa-step-backward": "◂", "fa fa-step-forward": "▸", "fa fa-play fa-flip-horizontal": "◀",
          "fa fa-play": "▶", "fa fa-pause": "⏸"}


def animation_html(fig, anim: FuncAnimation, html_id: str):
    """Render ``anim`` to an ``IPython.display.HTML`` player whose element ids use ``html_id``.

    The figure is closed afterwards, so the notebook shows the player only.
    """
    from IPython.display import HTML

    if not isinstance(anim, FuncAnimation):
        raise TypeError(f"anim: expected a matplotlib FuncAnimation (from animate_quad2d), got {type(anim).__name__}")
    if not isinstance(html_id, str) or not _HTML_ID.fullmatch(html_id):
        raise ValueError(f"html_id: expected a name of letters, digits and '_' (not starting with a digit), "
                         f"got {html_id!r}")
    html = anim.to_jshtml(default_mode="once")
    plt.close(fig)
    found = _RANDOM_ID.search(html)
    if found is None:
        raise RuntimeError("animation_html: matplotlib's player no longer names its image '_anim_img<id>'")
    html = _ICON_CSS.sub("", html.replace(found.group(1), html_id))
    for icon, text in _ICONS.items():
        html = html.replace(f'<i class="{icon}"></i>', text)
    return HTML(html)


def quad2d_geometry(phi: float, y: float, wall_y_m: float, arm_m: float = 0.3):
    """Body and range-beam end points of the 2D quadrotor seen from behind (y right, up on screen).

    A positive roll lowers the right (+y) arm (FRD); the beam leaves along the body's +y axis and
    hits the wall at height ``-(wall - y) tan φ``, after ``(wall - y) / cos φ`` metres (eq. 33).

    Returns
    -------
    body, beam : tuple of ([y0, y1], [up0, up1])
    range_m : float
    """
    phi, y, wall_y_m = (as_finite_number(n, v) for n, v in (("phi", phi), ("y", y), ("wall_y_m", wall_y_m)))
    arm_m = as_positive("arm_m", arm_m)
    c, s = np.cos(phi), np.sin(phi)
    body = ([y - arm_m * c, y + arm_m * c], [arm_m * s, -arm_m * s])
    beam = ([y, wall_y_m], [0.0, -(wall_y_m - y) * np.tan(phi)])
    return body, beam, (wall_y_m - y) / c


def animate_quad2d(t, x_true, wall_y_m: float, *, estimate=None, sigma=None, n_frames: int = 50,
                   dpi: int = 70, arm_m: float = 0.3):
    """Animate the 2D quadrotor seen from behind: body, range beam to the wall, estimate ±2σ.

    Parameters
    ----------
    t : (N,) times [s]
    x_true : (N, 3) true states ``[φ, ẏ, y]`` (chapter 9's model)
    wall_y_m : float
        Position of the wall the beam hits [m].
    estimate, sigma : (N, 3), optional
        An estimate and its standard deviations; ``ŷ ± 2σ_y`` is drawn under the body.
    n_frames : int
        Frames, evenly spaced over ``t`` (at most ``N``).
    dpi, arm_m : figure resolution and half-width of the drawn body [m].

    Returns
    -------
    (fig, FuncAnimation)
        Pass both to :func:`animation_html`.
    """
    t = as_times("t", t)
    x_true = as_finite_array("x_true", x_true, ndim=2)
    if x_true.shape != (t.size, 3):
        raise ValueError(f"x_true: expected shape ({t.size}, 3), got {x_true.shape}")
    if (estimate is None) != (sigma is None):
        raise ValueError("estimate, sigma: expected both or neither, got only one")
    if estimate is not None:
        estimate, sigma = as_finite_array("estimate", estimate, ndim=2), as_finite_array("sigma", sigma, ndim=2)
        for name, arr in (("estimate", estimate), ("sigma", sigma)):
            if arr.shape != x_true.shape:
                raise ValueError(f"{name}: expected shape {x_true.shape}, got {arr.shape}")
    n_frames = as_count("n_frames", n_frames, high=t.size)
    dpi = as_count("dpi", dpi)
    wall, arm_m = as_finite_number("wall_y_m", wall_y_m), as_positive("arm_m", arm_m)
    frames = np.linspace(0, t.size - 1, n_frames).round().astype(int)

    fig, ax = plt.subplots(figsize=(6, 2.2), dpi=dpi, layout="constrained")
    ax.set_xlim(min(x_true[:, 2].min(), wall) - 0.8, wall + 0.3)
    ax.set_ylim(-1.0, 0.6)
    ax.set_aspect("equal")
    ax.axvline(wall, color="0.3", lw=4)
    ax.set_xlabel("y [m]  (wall at right)")
    ax.set_yticks([])
    beam, = ax.plot([], [], color="C3", lw=1, ls="--", label="range beam")
    body, = ax.plot([], [], color="k", lw=3, solid_capstyle="round", label="drone (truth)")
    est, = ax.plot([], [], color="C0", lw=3, label="estimate of y ± 2σ")
    if estimate is None:
        est.set_label("_")
    ax.legend(loc="lower left", fontsize="x-small", ncol=3, frameon=False)
    label = ax.text(0.01, 0.97, "", transform=ax.transAxes, va="top", fontsize="small")

    def draw(k):
        body_yz, beam_yz, range_m = quad2d_geometry(x_true[k, 0], x_true[k, 2], wall, arm_m)
        body.set_data(*body_yz)
        beam.set_data(*beam_yz)
        if estimate is not None:
            half = 2.0 * sigma[k, 2]
            est.set_data([estimate[k, 2] - half, estimate[k, 2] + half], [-0.5, -0.5])
        label.set_text(f"t = {t[k]:4.1f} s   roll = {np.degrees(x_true[k, 0]):5.1f}°   range = {range_m:4.2f} m")
        return body, beam, est, label

    fig.canvas.draw()  # lay the figure out once: only artists inside the axes change between frames,
    fig.set_layout_engine("none")  # so re-running the constrained layout for every frame gains nothing
    return fig, FuncAnimation(fig, draw, frames=frames, interval=100, blit=True)
