"""`mbjax_harness.plot.animate.animate` draws every kind of system the reproductions animate: the
Carpal Wrist, a closed loop (its tree and cut joints) and a tree."""

import jax.numpy as jnp
import pytest
from PIL import Image

from mbjax.rigid import TreeSystem
from mbjax.model import chain
from mbjax.scenes import carpal_wrist, four_bar
from mbjax.wrist import WristSystem
from mbjax_harness.plot.animate import animate


@pytest.mark.parametrize("kind", ["wrist", "closed loop", "tree"])
def test_animate_draws_every_kind_of_system(kind, tmp_path):
    if kind == "wrist":
        system, q = WristSystem(carpal_wrist.wrist()), carpal_wrist.home()
    elif kind == "closed loop":
        system, q, _ = four_bar.build()
    else:
        system = TreeSystem(chain(3))
        q = system.neutral()
    qs = jnp.stack([q, q, q])
    path = animate(tmp_path / "a.gif", system, jnp.array([0.0, 0.1, 0.2]), qs, frames=3)
    with Image.open(path) as gif:
        assert gif.n_frames == 3


def test_write_gif_frames_match_a_full_redraw(tmp_path):
    """Blitting (the still parts drawn once, the moving artists over them) gives each frame as
    a full redraw of the figure would, the title included."""
    import numpy as np
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from mbjax_harness.plot.animate import write_gif

    def figure():
        fig = Figure(figsize=(2.0, 2.0))
        ax = fig.add_subplot(projection="3d")
        ax.set(xlim=(-1, 1), ylim=(-1, 1), zlim=(-1, 1))
        line = ax.plot([], [], [], "-o", color="k")[0]

        def draw(i):
            line.set_data_3d([0.0, np.cos(i)], [0.0, np.sin(i)], [0.0, 0.5])
            ax.title.set_text(f"frame {i}")
            return [line, ax.title]
        return fig, draw

    fig, draw = figure()
    with Image.open(write_gif(tmp_path / "a.gif", fig, draw, 3, fps=10, dpi=50)) as gif:
        frames = []
        for i in range(3):
            gif.seek(i)
            frames.append(np.asarray(gif.convert("RGB"), dtype=float))
    for i in range(3):
        full, draw_full = figure()
        full.set_dpi(50)
        draw_full(i)
        canvas = FigureCanvasAgg(full)
        canvas.draw()
        expected = np.asarray(canvas.buffer_rgba())[..., :3].astype(float)
        assert np.mean(np.abs(frames[i] - expected)) < 1.0
        assert np.mean(np.any(np.abs(frames[i] - expected) > 40, axis=-1)) < 2e-3
    assert np.mean(np.abs(frames[1] - frames[0])) > 0.1      # the line moved
