"""mbjax: differentiable multibody dynamics in JAX.

Kernels are pure functions of equinox modules and arrays, so `jax.jit`, `jax.vmap` and `jax.grad`
compose over all of them. mbjax changes no JAX setting: enable float64 yourself for accuracy work
(``jax.config.update("jax_enable_x64", True)``). Imported before JAX starts its backend, it sets
XLA's and JAX's CPU runtime options for small programs: loops compiled as one kernel, no
concurrency scheduling, the classic fusion emitter, synchronous dispatch (`mbjax.runtime`;
MBJAX_XLA_DEFAULTS=0 turns them off).
"""

from mbjax import runtime  # first: it sets XLA_FLAGS before anything can start JAX's backend
from mbjax import control, data, integrate, lie, model, rigid, scenes, spatial, tree
from mbjax.cache import use_compilation_cache
from mbjax.integrate import simulate
from mbjax.model import Model
from mbjax.model.mjcf import from_mujoco, load_mjcf
from mbjax.model.states import (
    state_from_mujoco,
    state_from_pinocchio,
    state_to_mujoco,
    state_to_pinocchio,
)
from mbjax.model.urdf import load_urdf
from mbjax.rigid import forward_dynamics, frame_jacobian, frame_pose, inverse_dynamics, mass_matrix

__version__ = "0.1.0"
__all__ = ["Model", "control", "data", "forward_dynamics", "frame_jacobian", "frame_pose",
           "from_mujoco", "integrate", "inverse_dynamics", "lie", "load_mjcf", "load_urdf",
           "mass_matrix", "model", "rigid", "runtime", "scenes", "simulate", "spatial", "state_from_mujoco",
           "state_from_pinocchio", "state_to_mujoco", "state_to_pinocchio", "tree",
           "use_compilation_cache"]
