"""The JAX peers of `mbjax bench speed` (mbjax/bench/jax_peers.py) read the same URDFs as
Pinocchio and agree with its `aba`, so the bench times the same dynamics."""

import importlib.util

import pytest

from mbjax_harness.bench.jax_peers import check_against_pinocchio
from mbjax.model import chain
from mbjax._src.model.urdf import to_urdf

needs = pytest.mark.skipif(not all(importlib.util.find_spec(m) for m in ("pinocchio", "jaxsim", "adam")),
                           reason="the bench extra's peers (pin, jaxsim, adam-robotics)")


@pytest.mark.slow
@needs
@pytest.mark.parametrize("seed", [None, 1])
def test_peers_agree_with_pinocchio_on_chains(tmp_path, seed):
    path = tmp_path / "chain.urdf"
    path.write_text(to_urdf(chain(7) if seed is None else chain(7, seed=seed)))
    errors = check_against_pinocchio(str(path))
    assert errors["jaxsim"] < 1e-12 and errors["adam"] < 1e-12


@pytest.mark.slow
@needs
def test_peers_agree_with_pinocchio_on_the_panda():
    from mbjax_harness.reproduce.urdf_corpus import corpus_paths
    panda = next(p for p in corpus_paths() if p.stem == "panda")
    for floating in (False, True):
        errors = check_against_pinocchio(str(panda), floating=floating)
        assert errors["jaxsim"] < 1e-12 and errors["adam"] < 1e-12
