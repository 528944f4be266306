"""`mbjax reproduce gradient-matrix`: `jax.grad` and `jax.jacfwd` through `simulate`, checked.
For every system, every integrator and every loop method, projection included, against central
finite differences.

Each cell differentiates one scalar of a short rollout (a smooth function of the final q and u)
with respect to three parameters at once: p[0] perturbs the initial state, p[1] scales a control
parameter (a gain, a spline's knots, a constant torque) and p[2] a model parameter (a mass, a
modal stiffness, the wrist's tool mass). The matrix covers every system with RK4 (a rigid body,
a revolute tree, a quaternion tree, a flexible tree, the Carpal Wrist, a rigid and a flexible
closed loop), every integrator on the quaternion tree and on the projected four-bar, and every
loop method (`Coupled`, with Baumgarte's terms, `Momentum`, `Stabilized` with epsilon = 0 and
with the epsilon-dynamics) with and without projection. `QUICK_CELLS`, a cheap subset, is what
the default test suite and `--quick` run.

JSON: {"cells": [{"name", "system", "integrator", "method", "projection", "grad", "jacfwd",
"finite_differences", "grad_error", "jacfwd_error", "finite", "seconds"}], "step", "tolerance"};
the errors are max |d - fd| / max |fd|; "seconds" is compilation plus one run of grad, jacfwd and
the six perturbed rollouts together.
"""

import functools
import json
import time
from collections.abc import Callable
from pathlib import Path
from typing import NamedTuple

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from mbjax.control import PD, Constant, CubicSpline
from mbjax.flex import Beam, FlexibleModel, FlexibleSystem, beam_body, craig_bampton
from mbjax.integrate import INTEGRATORS, simulate
from mbjax.loops import ClosedSystem, Coupled, Momentum, Stabilized
from mbjax.model import Model, chain
from mbjax_harness.progress import step
from mbjax.rigid import RigidBody, TreeSystem
from mbjax.scenes import carpal_wrist as cw
from mbjax.scenes import flexible_slider_crank as fsc
from mbjax.scenes import four_bar
from mbjax.wrist import WristSystem

NAME = "gradient-matrix"
STEP = 1e-5                # central differences: truncation ~1e-10, round-off ~1e-11
TOLERANCE = 1e-5           # relative, float64


def _scalar(sol):
    """A smooth scalar of the final state that every coordinate enters."""
    q, u = sol.qs[-1], sol.vs[-1]
    return jnp.sum(jnp.sin(q) * jnp.arange(1, q.shape[0] + 1)) + 0.1 * jnp.sum(u**2)


def _run(system, integrator, q0, u0, dt, steps):
    t1 = dt * steps
    return _scalar(simulate(system, integrator, q0, u0, dt=dt, t1=t1, saveat=[t1]))


# -- the systems ------------------------------------------------------------------------------------

def rigid_body(p, integrator):
    """A heavy top (quaternion) under a constant body torque."""
    body = RigidBody(1.0 + p[2], np.diag([0.3, 0.4, 0.2]), com=(0.02, 0.01, 0.1), fixed_point=True,
                     control=Constant(jnp.array([0.1, -0.2, 0.05]) * (1.0 + p[1])))
    q0, u0 = body.initial_state(np.eye(3), jnp.array([0.5 + p[0], 0.2, 8.0]))
    return _run(body, integrator, q0, u0, 0.01, 10)


def tree(p, integrator):
    """A random revolute chain under a PD servo."""
    model = chain(3, seed=1)
    model = eqx.tree_at(lambda m: m.mass, model, model.mass.at[1].multiply(1.0 + p[2]))
    system = TreeSystem(model, PD(5.0 * (1.0 + p[1]), 0.5, jnp.zeros(3)))
    return _run(system, integrator, jnp.array([0.3 + p[0], -0.2, 0.1]), jnp.zeros(3), 0.01, 10)


def quaternion_tree(p, integrator):
    """A spherical root joint (a quaternion, retracted in RKMK4's chart) carrying a hinge, a PD
    on the hinge only (`actuation`) and a growing external force on the last body."""
    base = chain(2, joint_types=("spherical", "revolute"), seed=2)
    model = eqx.tree_at(lambda m: m.mass, base, base.mass.at[1].multiply(1.0 + p[2]))
    push = jnp.zeros((2, 6)).at[1, 3].set(0.5)
    system = TreeSystem(model, PD(2.0 * (1.0 + p[1]), 0.1, jnp.zeros(1), q_index=[4], v_index=[3]),
                        actuation=[3], external=lambda t, q, v: push * (1.0 + t))
    q0 = model.retract(model.neutral(), jnp.array([0.2 + p[0], -0.1, 0.3, 0.4]))
    return _run(system, integrator, q0, jnp.array([0.5, 0.0, -0.3, 0.2]), 0.01, 10)


def _built_once(build):
    """A scene built once, eagerly even when first asked for inside a traced loss (a beam's modal
    reduction traced into every gradient program would be compiled with it)."""
    @functools.cache
    def cached():
        with jax.ensure_compile_time_eval():
            return build()
    return cached


@_built_once
def _beam_on_a_hinge() -> FlexibleModel:
    beam = Beam.round(1.0, 0.02, E=7e10, rho=2700.0, nu=0.33, n_elements=2)
    body = beam_body(beam, craig_bampton(beam, n_modes=2, planar="xz"))
    hinge = Model([-1], ["revolute"], mass=[0.85], com=[[0.5, 0, 0]], inertia=[np.eye(3) * 0.07],
                  axis=[[0, 1, 0]])
    return FlexibleModel(hinge, {0: body})


def flexible(p, integrator):
    """A beam on a hinge driven by a torque spline, geometric stiffening on."""
    base = _beam_on_a_hinge()
    model = eqx.tree_at(lambda m: m.bodies.stiffness, base, base.bodies.stiffness * (1.0 + p[2]))
    spline = CubicSpline(jnp.array([[0.0], [2.0], [-1.0], [0.5], [1.0]]) * (1.0 + p[1]), 0.02)
    system = FlexibleSystem(model, spline, actuation=[0])
    q0 = jnp.zeros(model.nq).at[1].set(1e-3 * (1.0 + p[0]))
    return _run(system, integrator, q0, jnp.zeros(model.nv), 2e-4, 10)


_servo = _built_once(cw.servo)
_four_bar = _built_once(four_bar.build)
_slider_crank = _built_once(lambda: fsc.build(n_elements=1))


def wrist(p, integrator):
    """The Carpal Wrist under its servo plus a torque spline."""
    servoed, theta0, _ = _servo()
    w = eqx.tree_at(lambda w: w.tool_mass, servoed.model, servoed.model.tool_mass * (1.0 + p[2]))
    feedforward = CubicSpline(jnp.array([[0.1, -0.1, 0.0], [0.3, 0.0, -0.2], [0.0, 0.2, 0.1],
                                         [-0.1, 0.1, 0.0]]) * (1.0 + p[1]), 0.1)
    system = WristSystem(w, servoed.control + feedforward)
    return _run(system, integrator, theta0.at[0].add(p[0]), jnp.zeros(3), 0.01, 10)


def closed(method, projection: bool):
    """The four-bar driven by a constant crank torque, closed by `method`."""
    def loss(p, integrator):
        system0, q0, v0 = _four_bar()
        model = system0.tree.model
        model = eqx.tree_at(lambda m: m.mass, model, model.mass.at[1].multiply(1.0 + p[2]))
        tree_ = TreeSystem(model, Constant(jnp.array([0.2 * (1.0 + p[1])])), actuation=[0])
        system = ClosedSystem(tree_, system0.closures, method, projection)
        v = v0 * (1.0 + p[0])
        return _run(system, integrator, q0, system.initial_state(q0, v), 1e-3, 10)
    return loss


def closed_flexible(projection: bool):
    """The flexible slider-crank (driven crank, the slider at a marker of the rod, one element)
    closed by Anderson 1993's route, a torque on the rod's joint."""
    def loss(p, integrator):
        system0, q0, v0, _ = _slider_crank()
        model = system0.tree.model
        model = eqx.tree_at(lambda m: m.bodies.stiffness, model, model.bodies.stiffness * (1.0 + p[2]))
        tree_ = FlexibleSystem(model, Constant(jnp.array([0.05 * (1.0 + p[1])])), actuation=[1])
        system = ClosedSystem(tree_, system0.closures, Stabilized(), projection)
        return _run(system, integrator, q0, v0.at[2].add(p[0]), 1e-5, 10)
    return loss


class Cell(NamedTuple):
    system: str
    integrator: str
    method: str
    projection: bool
    loss: Callable

    @property
    def name(self) -> str:
        extra = f", {self.method}, projection {'on' if self.projection else 'off'}" if self.method else ""
        return f"{self.system}{extra}, {self.integrator}"


METHODS = {"coupled": Coupled(), "baumgarte": Coupled(baumgarte=(20.0, 20.0)), "momentum": Momentum(),
           "stabilized": Stabilized(), "epsilon": Stabilized(epsilon=1.0, kappa=10.0)}

_CELLS = ([Cell("quaternion tree", name, "", False, quaternion_tree) for name in INTEGRATORS]
          + [Cell("rigid body", "rkmk4", "", False, rigid_body), Cell("tree", "rk4", "", False, tree),
             Cell("flexible", "rk4", "", False, flexible), Cell("wrist", "rk4", "", False, wrist)]
          + [Cell("four-bar", "rk4", label, proj, closed(method, proj))
             for label, method in METHODS.items() for proj in (False, True)]
          + [Cell("four-bar", name, "coupled", True, closed(Coupled(), True))
             for name in INTEGRATORS if name != "rk4"]
          + [Cell("flexible slider-crank", "rk4", "stabilized", proj, closed_flexible(proj))
             for proj in (False, True)])
CELLS = {cell.name: cell for cell in _CELLS}

# What the default test suite runs: the cheapest cells through each kind of machinery (an explicit
# and a staged integrator on a quaternion tree, RKMK4's chart on a rigid body, and the
# O(n + m^3) route through the differentiable projection). The dense multipliers' gradient through
# a four-bar rollout is checked against central differences in tests/loops/test_coupled.py.
QUICK_CELLS = ("quaternion tree, explicit_euler", "quaternion tree, rk4", "rigid body, rkmk4",
               "four-bar, stabilized, projection on, rk4")


def check(cell: Cell, step: float = STEP) -> dict:
    """grad, jacfwd and central differences of one cell, in one compiled call."""
    integrator = INTEGRATORS[cell.integrator]()

    def loss(p):
        return cell.loss(p, integrator)

    @jax.jit
    def everything(p):
        steps = step * jnp.concatenate([jnp.eye(3), -jnp.eye(3)])
        values = jax.vmap(loss)(p + steps)
        return jax.grad(loss)(p), jax.jacfwd(loss)(p), (values[:3] - values[3:]) / (2 * step)

    start = time.perf_counter()
    grad, jacfwd, fd = (np.asarray(x) for x in everything(jnp.zeros(3)))
    seconds = time.perf_counter() - start
    scale = float(np.abs(fd).max())
    return {"name": cell.name, "system": cell.system, "integrator": cell.integrator,
            "method": cell.method or None, "projection": cell.projection,
            "grad": grad.tolist(), "jacfwd": jacfwd.tolist(), "finite_differences": fd.tolist(),
            "grad_error": float(np.abs(grad - fd).max() / scale),
            "jacfwd_error": float(np.abs(jacfwd - fd).max() / scale),
            "finite": bool(np.all(np.isfinite(grad)) and np.all(np.isfinite(jacfwd))),
            "seconds": seconds}


def reproduce(out: Path, quick: bool = False) -> dict:
    """Every cell (quick: `QUICK_CELLS`); writes NAME.json and NAME.png."""
    from mbjax_harness.plot.gradients import gradient_matrix_figure

    names = QUICK_CELLS if quick else tuple(CELLS)
    cells = []
    for name in names:
        step(name)
        cells.append(check(CELLS[name]))
    data = {"step": STEP, "tolerance": TOLERANCE, "cells": cells}
    out.mkdir(parents=True, exist_ok=True)
    (out / f"{NAME}.json").write_text(json.dumps(data, indent=1))
    gradient_matrix_figure(data).savefig(out / f"{NAME}.png", dpi=110)
    return data
