"""Where one contact evaluation of gymnasium's Ant goes (issue 58's throughput target): each
stage called 500 times inside one compiled `lax.fori_loop` (a state nudged each time, so nothing
is hoisted), the best of three loops, per call. Outside a loop a call from Python costs some
60 us more (the system's pytree flattened and dispatched).

    python benchmarks/bench_contact_profile.py
"""

import time
import warnings

import jax
import jax.numpy as jnp

import mbjax
from mbjax.contact import ContactSystem
from mbjax.rigid import TreeSystem

jax.config.update("jax_enable_x64", True)
CALLS = 500


def per_call(fn, q, v) -> float:
    """Seconds per call of fn(q, v) in a compiled loop."""
    def body(i, total):
        out = fn(q.at[2].add(1e-9 * i), v)
        return total + sum(jnp.sum(x) for x in jax.tree.leaves(out))

    loop = jax.jit(lambda: jax.lax.fori_loop(0, CALLS, body, 0.0))
    jax.block_until_ready(loop())
    best = float("inf")
    for _ in range(3):
        start = time.perf_counter()
        jax.block_until_ready(loop())
        best = min(best, time.perf_counter() - start)
    return best / CALLS


def main() -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ant = mbjax.load_mjcf(mbjax.data.ANT)
    system = ContactSystem(TreeSystem(ant), timestep=0.01)
    q = ant.neutral().at[2].set(0.55).at[7:].set(jnp.array([0, 1.0, 0, -1, 0, -1, 0, 1]))
    v = jnp.zeros(ant.nv).at[0].set(0.3)
    stages = {
        "acceleration (everything)": lambda q, v: system.acceleration(0.0, q, v),
        "contact detection": lambda q, v: jax.tree.leaves(system.contacts(q)),
        "mass matrix": lambda q, v: system.tree.mass_matrix(q),
        "bias forces": lambda q, v: system.tree.bias(0.0, q, v),
    }
    for name, fn in stages.items():
        print(f"{name}: {per_call(fn, q, v) * 1e6:.1f} us")


if __name__ == "__main__":
    main()
