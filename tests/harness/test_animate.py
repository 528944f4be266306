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
