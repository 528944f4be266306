"""`mbjax._src.runtime`: the XLA CPU options mbjax sets at import, and `mbjax bench speed`'s HLO reader."""

import json
import os
import subprocess
import sys

import jax
import jax.numpy as jnp
import pytest

from mbjax._src import runtime
from mbjax_harness.bench.speed import kernel_counts

# A float64 rollout of the 7-link chain, printed bit for bit, with what the process's XLA_FLAGS
# became on `import mbjax`.
SCRIPT = """
import json, os, jax
jax.config.update("jax_enable_x64", True)
import mbjax
from mbjax.model import chain
m = chain(7)
def step(s, _):
    q, v = s
    v = v + 1e-3 * mbjax.forward_dynamics(m, q, v, 0 * v)
    return (q + 1e-3 * v, v), None
q = jax.jit(lambda q: jax.lax.scan(step, (q, 0 * q), None, length=200)[0][0])(0.3 + 0 * m.neutral())
print(json.dumps({"flags": os.environ.get("XLA_FLAGS"), "applied": mbjax._src.runtime.applied(),
                  "synchronous": mbjax._src.runtime.synchronous(),
                  "q": [float(x).hex() for x in q]}))
"""


def _run(**env) -> dict:
    environment = {k: v for k, v in os.environ.items()
                   if k not in ("XLA_FLAGS", "MBJAX_XLA_DEFAULTS", "JAX_CPU_ENABLE_ASYNC_DISPATCH")}
    out = subprocess.run([sys.executable, "-c", SCRIPT], env={**environment, **env},
                         capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


@pytest.mark.skipif(runtime._jaxlib_version() not in runtime.TESTED,
                    reason="the flag is set only on jaxlib releases known to have it")
def test_import_sets_the_flag_and_changes_no_result():
    """`import mbjax` adds its flags to XLA_FLAGS and makes CPU dispatch synchronous; the user's
    own settings (flag by flag) and MBJAX_XLA_DEFAULTS=0 win; the same rollout gives the same
    numbers either way (to the last bit where only the scheduling or the dispatch changes)."""
    default = _run()
    assert default["applied"] and default["flags"] == runtime.FLAG and default["synchronous"]
    off = _run(MBJAX_XLA_DEFAULTS="0")
    assert not off["applied"] and off["flags"] is None and not off["synchronous"]
    asynchronous = _run(JAX_CPU_ENABLE_ASYNC_DISPATCH="1")
    assert asynchronous["applied"] and not asynchronous["synchronous"]
    mine = "--xla_cpu_enable_concurrency_optimized_scheduler=true"
    own = _run(XLA_FLAGS=mine)
    assert not own["applied"]
    assert own["flags"] == " ".join([mine, runtime.FLAGS[0], *runtime.FLAGS[2:]])   # the others still added
    mine = "--xla_backend_extra_options=xla_cpu_small_while_loop_byte_threshold=2000"
    own_options = _run(XLA_FLAGS=mine)
    assert own_options["flags"] == " ".join([mine, *runtime.FLAGS[1:]])
    # kernels scheduled either way, dispatch either way: the same numbers bit for bit
    assert default["q"] == own["q"] == asynchronous["q"]
    # loops compiled as one kernel or as many, and XLA's two fusion emitters, round some
    # operations differently: a few ulps after 200 steps
    for other in (off, own_options):
        assert max(abs(float.fromhex(a) - float.fromhex(b))
                   for a, b in zip(default["q"], other["q"], strict=True)) < 1e-13


def test_no_flag_once_the_backend_runs(monkeypatch):
    """XLA reads XLA_FLAGS once: after the backend has started, configure_xla leaves it alone."""
    jnp.zeros(1).block_until_ready()
    monkeypatch.delenv("XLA_FLAGS", raising=False)
    monkeypatch.delenv("MBJAX_XLA_DEFAULTS", raising=False)
    assert not runtime.configure_xla()
    assert "XLA_FLAGS" not in os.environ


def test_kernel_counts_reads_loop_bodies():
    """A scan whose body is one matrix product and one elementwise op: either XLA compiled the
    loop as one kernel, or its body has kernels of its own, counted apart from the entry's."""
    def f(A, x):
        return jax.lax.scan(lambda x, _: (jnp.tanh(A @ x), None), x, None, length=5)[0]

    A, x = jnp.eye(3), jnp.ones(3)
    counts = kernel_counts(jax.jit(f).lower(A, x).compile().as_text())
    assert len(counts["per_step"]) + counts["one_kernel_loops"] == 1
    assert all(1 <= k <= 8 for k in counts["per_step"])
    assert counts["entry"] >= 1


def test_a_loop_over_contact_knots_compiles_a_steps_repeated_passes_once():
    """Item 5: a stance step runs the tree's passes several times on one state, which XLA
    merges where the step stands alone; inside a loop over knots its loop-invariant code motion
    kept the copies apart (65 matrix products for 27 on a 4-link chain held at its tip). With
    `CONTACT_OPTIONS` the loop's body compiles what the step alone does; `contact_jit` picks
    them for programs that solve contacts, on a CPU."""
    import equinox as eqx

    import mbjax
    from mbjax.contact import PointContact, stance
    from mbjax.integrate import SemiImplicitEuler
    from mbjax.rigid import TreeSystem
    from mbjax.trajopt import Knot, control_residual

    q0 = jnp.full(4, 0.3)
    knot = Knot(stance(TreeSystem(mbjax.model.chain(4)), q0, [PointContact("body3")]),
                control_residual(4))

    def step(knot, q, v, u):
        return knot.advance(SemiImplicitEuler(), 0.0, q, v, u, jnp.asarray(0.01))[:2]

    def looped(knot, qs, vs, us):
        return jax.lax.map(lambda a: step(knot, *a), (qs, vs, us))

    def products(jitted, *args) -> int:
        return jitted.lower(*args).lowered.compile().as_text().count(" dot(")

    qs, zeros = jnp.tile(q0, (5, 1)), jnp.zeros((5, 4))
    alone = products(eqx.filter_jit(step), knot, q0, zeros[0], zeros[0])
    pick = runtime.contact_jit(looped)
    args = (knot, qs, zeros, zeros)
    assert products(pick(True, *args), *args) == alone
    assert products(pick(False, *args), *args) > alone     # XLA's default, as measured
    # inside another jit the outer program's compilation decides (options are top-level only)
    nested = jax.jit(lambda qs: pick(True, knot, qs, zeros, zeros)(knot, qs, zeros, zeros))
    assert nested(qs)[0].shape == qs.shape
