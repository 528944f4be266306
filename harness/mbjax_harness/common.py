"""What the benchmark suites (`mbjax_harness.bench`) and the reproductions
(`mbjax_harness.reproduce`) share, so that neither imports the other:

- the rigid chains' workloads: random states (`states`), the strategy each method name stands for
  (`STRATEGY`) and forward dynamics looped inside one jitted call (`looped_fn`, `loop_length`),
  for `mbjax bench rigid`, `mbjax bench throughput`, `mbjax bench speed` and `mbjax reproduce
  tree-scaling`;
- the URDFs example-robot-data ships (`corpus_paths`), for `mbjax reproduce urdf-corpus` and
  `mbjax bench speed`;
- the sleeping top's long-run setting (`SPIN_RATIO`, `DT`, `NODES`, `TILT0`, `steady_rotation`),
  for `mbjax reproduce top-long-run` and `mbjax bench accuracy`.

Timing helpers (`measure`, `timed`, `in_turns`) are in `mbjax_harness.timing`.
"""

from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np

from mbjax import Dense, Recursive
from mbjax.rigid import forward_dynamics
from mbjax.tfe import Reference

# -- rigid chains -------------------------------------------------------------------------------

# the strategy each method name stands for (the records keep the names)
STRATEGY = {"recursive": Recursive(), "dense": Dense()}
SEED = 0


def states(n: int, batch: int, seed: int = SEED):
    """(q, v, tau), each (batch, n): angles in [-pi, pi), unit-normal rates and torques."""
    rng = np.random.default_rng(seed + n)
    return (rng.uniform(-np.pi, np.pi, (batch, n)), rng.normal(size=(batch, n)),
            rng.normal(size=(batch, n)))


def looped_fn(method: str, evaluations: int):
    """`evaluations` forward-dynamics calls in one jitted `fori_loop`, each at a velocity nudged by
    the previous result (so none can be hoisted or skipped): its run time over `evaluations` is the
    cost of one evaluation as a simulation or optimisation loop meets it, without the per-call
    dispatch of `single_fn` (tens of us on CPU, more than the whole recursion for small n)."""
    def run(model, q, v, tau):
        def body(_, acc):
            return forward_dynamics(model, q, v + 1e-12 * acc, tau, method=STRATEGY[method])
        return jax.lax.fori_loop(0, evaluations, body, jnp.zeros_like(v))

    return jax.jit(run)


def loop_length(n: int) -> int:
    """Evaluations per looped call: about 4000 body-evaluations, at least 4."""
    return max(4, 4000 // n)


# -- the URDF corpus ----------------------------------------------------------------------------

def corpus_paths() -> list[Path]:
    """Every URDF that the example-robot-data package ships (PackageNotFoundError when it is
    not installed)."""
    from importlib.metadata import distribution
    root = Path(distribution("example-robot-data").locate_file(
        "cmeel.prefix/share/example-robot-data/robots"))
    return sorted(root.rglob("*.urdf"))


# -- the sleeping top's long run (Borri 1990 §6-8) ----------------------------------------------

SPIN_RATIO = 1.01
DT = 0.5
NODES = 2
TILT0 = 1e-4


def steady_rotation(spin) -> Reference:
    """R_o = exp(Omega t e_3) (eq 7.1)."""
    return Reference(jnp.eye(3), jnp.zeros(3), jnp.array([0.0, 0.0, spin]), jnp.zeros(3))
