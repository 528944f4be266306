"""mbjax: differentiable multibody dynamics in JAX.

Kernels are pure functions of equinox modules and arrays, so `jax.jit`, `jax.vmap` and `jax.grad`
compose over all of them. mbjax changes no JAX setting: enable float64 yourself for accuracy work
(``jax.config.update("jax_enable_x64", True)``). Imported before JAX starts its backend, it sets
XLA's and JAX's CPU runtime options for small programs: loops compiled as one kernel, no
concurrency scheduling, the classic fusion emitter, synchronous dispatch (MBJAX_XLA_DEFAULTS=0
turns them off).

The names below are the everyday ones; each topic has its namespace: `mbjax.lie`, `mbjax.model`,
`mbjax.control`, `mbjax.contact`, `mbjax.rigid`, `mbjax.flex`, `mbjax.loops`, `mbjax.tfe`, `mbjax.wrist`,
`mbjax.integrate`, `mbjax.trajopt`, `mbjax.gaits`, `mbjax.scenes`, `mbjax.data`.
"""

from mbjax._src import runtime as _runtime  # first: it sets XLA_FLAGS before JAX starts its backend

from mbjax import contact as contact
from mbjax import control as control
from mbjax import data as data
from mbjax import flex as flex
from mbjax import gaits as gaits
from mbjax import integrate as integrate
from mbjax import lie as lie
from mbjax import loops as loops
from mbjax import model as model
from mbjax import rigid as rigid
from mbjax import scenes as scenes
from mbjax import tfe as tfe
from mbjax import trajopt as trajopt
from mbjax import wrist as wrist
from mbjax._src.cache import use_compilation_cache as use_compilation_cache
from mbjax._src.integrate.simulate import simulate as simulate
from mbjax._src.model.mjcf import load_mjcf as load_mjcf
from mbjax._src.model.model import Model as Model
from mbjax._src.model.urdf import load_urdf as load_urdf
from mbjax._src.rigid.dynamics import forward_dynamics as forward_dynamics
from mbjax._src.rigid.dynamics import inverse_dynamics as inverse_dynamics
from mbjax._src.rigid.dynamics import mass_matrix as mass_matrix
from mbjax._src.system.dynamics import AbstractForwardDynamics as AbstractForwardDynamics
from mbjax._src.system.dynamics import Auto as Auto
from mbjax._src.system.dynamics import Dense as Dense
from mbjax._src.system.dynamics import Recursive as Recursive
from mbjax._src.system.status import Status as Status
from mbjax._src.system.system import AbstractSystem as AbstractSystem
from mbjax._src.system.tree_system import AbstractTreeSystem as AbstractTreeSystem

del _runtime

__version__ = "0.1.0"
__all__ = [
    "AbstractForwardDynamics", "AbstractSystem", "AbstractTreeSystem", "Auto", "Dense", "Model",
    "Recursive", "Status", "forward_dynamics", "inverse_dynamics", "load_mjcf", "load_urdf",
    "mass_matrix", "simulate", "use_compilation_cache",
]
