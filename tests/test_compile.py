"""What a user's first calls compile: the public functions, called outside `jax.jit` as in a
notebook, compile one program each, and building a model compiles none (before, each array
operation compiled a program of its own: about 50 for one `forward_dynamics` call, which then
cost 0.2 s a call against 17 us now)."""

import json
import os
import subprocess
import sys

# In a fresh process (no program compiled yet, no persistent cache): the number of programs XLA
# compiles (or loads) for each call, from JAX's own compile events.
SCRIPT = """
import json
import jax
jax.config.update("jax_enable_x64", True)
import numpy as np
from jax import monitoring

import mbjax
from mbjax import lie
from mbjax.model import chain
from mbjax.rigid import forward_kinematics, frame_jacobian, frame_pose
from mbjax._src.rigid import energy

compiled = []
monitoring.register_event_duration_secs_listener(
    lambda event, duration, **kw: compiled.append(event)
    if event == "/jax/core/compile/backend_compile_duration" else None)

def programs(fn):
    start = len(compiled)
    jax.block_until_ready(fn())
    return len(compiled) - start

rng = np.random.default_rng(0)
q, v, tau = (rng.uniform(-1, 1, 5) for _ in range(3))
counts = {"chain(5)": programs(lambda: chain(5).mass)}
model = chain(5)
counts.update({
    "forward_dynamics": programs(lambda: mbjax.forward_dynamics(model, q, v, tau)),
    "forward_dynamics again": programs(lambda: mbjax.forward_dynamics(model, q, v, tau)),
    "inverse_dynamics": programs(lambda: mbjax.inverse_dynamics(model, q, v, tau)),
    "mass_matrix": programs(lambda: mbjax.mass_matrix(model, q)),
    "forward_kinematics": programs(lambda: forward_kinematics(model, q)),
    "energy": programs(lambda: energy(model, q, v)),
    "lie.exp": programs(lambda: lie.exp(np.array([0.1, 0.2, 0.3]))),
    "lie.log": programs(lambda: lie.log(np.eye(3), check=False)),
    "lie.quat_from_matrix": programs(lambda: lie.quat_from_matrix(np.eye(3))),
    "frame_pose": programs(lambda: frame_pose(model, q, "body4")),
    "frame_jacobian": programs(lambda: frame_jacobian(model, q, "joint2")),
})
# one program serves every frame of a model (the name is resolved outside the trace)
counts.update({
    "frame_pose another frame": programs(lambda: frame_pose(model, q, "joint1")),
    "frame_jacobian another frame": programs(lambda: frame_jacobian(model, q, "body0")),
})
print(json.dumps(counts))
"""


def test_public_functions_called_outside_jit_compile_one_program():
    no_cache = {"MBJAX_NO_CACHE": "1", "JAX_ENABLE_COMPILATION_CACHE": "false"}
    out = subprocess.run([sys.executable, "-c", SCRIPT], env={**os.environ, **no_cache},
                         capture_output=True, text=True, check=True)
    counts = json.loads(out.stdout.strip().splitlines()[-1])
    assert counts.pop("chain(5)") == 0
    assert counts.pop("forward_dynamics again") == 0
    assert counts.pop("frame_pose another frame") == 0
    assert counts.pop("frame_jacobian another frame") == 0
    assert counts == dict.fromkeys(counts, 1), counts
