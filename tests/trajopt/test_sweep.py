"""`mbjax.trajopt.sweep` for any pytree of parameters: a plain dict, checked against single
calls; errors for leaves without a shared variant axis; and the same sweep across two local
processes with `jax.distributed` (benchmarks/sweep_distributed.py) against one process."""

import json
import socket
import subprocess
import sys
from pathlib import Path

import jax.numpy as jnp
import numpy as np
import pytest

from mbjax.trajopt import sweep
from mbjax._src.trajopt.sweep import size

SCRIPT = Path(__file__).parents[2] / "benchmarks" / "sweep_distributed.py"
sys.path.insert(0, str(SCRIPT.parent))
import sweep_distributed  # noqa: E402  (the script's own functions, run here in one process)


def test_a_dict_of_parameters_matches_single_calls():
    params = {"scale": jnp.linspace(0.5, 2.0, 5), "offset": jnp.arange(5.0)[:, None] * jnp.ones(3)}
    out = sweep(lambda p: p["scale"] * jnp.sum(p["offset"]), params)
    np.testing.assert_allclose(np.asarray(out), np.linspace(0.5, 2.0, 5) * 3 * np.arange(5.0))
    torques = sweep(sweep_distributed.holding_torques, sweep_distributed.variants(4))
    for i, scale in enumerate(np.linspace(0.5, 2.0, 4)):
        one = sweep_distributed.holding_torques({"scale": jnp.asarray(scale)})
        np.testing.assert_allclose(np.asarray(torques[i]), np.asarray(one), rtol=1e-13, atol=1e-12)


def test_parameters_need_one_shared_variant_axis():
    with pytest.raises(ValueError, match="leading"):
        size({"a": jnp.zeros(3), "b": jnp.zeros(4)})
    with pytest.raises(ValueError, match="leading"):
        sweep(lambda p: p, {"a": jnp.asarray(1.0)})


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("localhost", 0))
        return s.getsockname()[1]


def test_the_sweep_across_two_processes_equals_one_process(tmp_path):
    out = tmp_path / "sweep.json"
    common = ["--processes", "2", "--coordinator", f"localhost:{_free_port()}",
              "--variants", "9", "--out", str(out)]
    procs = [subprocess.Popen([sys.executable, str(SCRIPT), "--process-id", str(i), *common],
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
             for i in range(2)]
    for p in procs:
        _, err = p.communicate(timeout=300)
        assert p.returncode == 0, err[-3000:]
    data = json.loads(out.read_text())
    assert data["processes"] == 2 and data["devices"] == 2
    expected = sweep(sweep_distributed.holding_torques, sweep_distributed.variants(9))
    np.testing.assert_allclose(np.asarray(data["torques"]), np.asarray(expected), rtol=1e-13,
                               atol=1e-12)
