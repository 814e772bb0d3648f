import matplotlib.pyplot as plt
import numpy as np
import pytest

from quadlib.quad.quad2d import quad2d_range_sensor
from quadlib.teaching.animation import animate_quad2d, animation_html, quad2d_geometry


def _flight(n=30):
    t = np.linspace(0.0, 3.0, n)
    x = np.column_stack([np.radians(20.0) * np.sin(t), np.zeros(n), np.linspace(0.0, 2.0, n)])
    return t, x


def test_quad2d_animation_is_deterministic_html_with_the_given_id():
    t, x = _flight()
    pages = []
    for _ in range(2):
        fig, anim = animate_quad2d(t, x, 5.0, estimate=x + 0.1, sigma=np.full_like(x, 0.05), n_frames=4, dpi=20)
        pages.append(animation_html(fig, anim, "quad2d_test").data)
        assert not plt.fignum_exists(fig.number)  # closed: only the player is shown
    assert pages[0] == pages[1]
    assert 'id="_anim_imgquad2d_test"' in pages[0]
    assert pages[0].count("data:image/png;base64") == 4
    assert "http" not in pages[0] and 'class="fa' not in pages[0]  # offline: no CDN icons
    assert "▶" in pages[0] and "⏸" in pages[0]


def test_quad2d_geometry_beam_reaches_the_wall_along_the_tilted_body():
    phi = np.radians(20.0)
    body, beam, range_m = quad2d_geometry(phi, 2.0, 5.0)
    np.testing.assert_allclose(beam[0], [2.0, 5.0])
    np.testing.assert_allclose(beam[1], [0.0, -3.0 * np.tan(phi)])  # positive roll tilts the beam down
    assert body[1][1] < 0 < body[1][0]  # the right (+y) arm is the lower one
    assert range_m == pytest.approx(np.hypot(3.0, beam[1][1]))  # beam length = eq. (33)
    assert range_m == pytest.approx(quad2d_range_sensor(0.01).h([phi, 0.0, 2.0])[0])


def test_quad2d_animation_names_bad_arguments():
    t, x = _flight()
    with pytest.raises(ValueError, match=r"x_true: expected shape \(30, 3\), got \(30, 2\)"):
        animate_quad2d(t, x[:, :2], 5.0)
    with pytest.raises(ValueError, match="estimate, sigma: expected both or neither"):
        animate_quad2d(t, x, 5.0, estimate=x)
    with pytest.raises(ValueError, match=r"n_frames: expected an int in \[1, 30\], got 31"):
        animate_quad2d(t, x, 5.0, n_frames=31)
    fig, anim = animate_quad2d(t, x, 5.0, n_frames=2, dpi=20)
    with pytest.raises(ValueError, match="html_id: expected a name of letters"):
        animation_html(fig, anim, "2 bad")
    plt.close(fig)
