"""mbjax: differentiable multibody dynamics in JAX.

Kernels are pure functions of equinox modules and arrays, so `jax.jit`, `jax.vmap` and `jax.grad`
compose over all of them. mbjax does not change global JAX settings: enable float64 yourself for
accuracy work (``jax.config.update("jax_enable_x64", True)``).
"""

from mbjax import integrate, lie, rigid, scenes
from mbjax.integrate import simulate

__version__ = "0.1.0"
__all__ = ["integrate", "lie", "rigid", "scenes", "simulate"]
