"""The knots of a problem: each step's own system and running cost, and the impulse of a
touchdown; grouped into phases so that each distinct phase compiles once (a problem of one
system is one phase of one knot repeated)."""

import abc
import dataclasses
import enum
import os
import sys
import warnings
from collections.abc import Callable, Sequence
from pathlib import Path

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jax import Array

from mbjax._src.contact.contact import AbstractContact
from mbjax._src.contact.impulse import impulse_map
from mbjax._src.contact.stance import contact_wrenches, is_stance, stance_wrenches
from mbjax._src.control import Constant
from mbjax._src.model.model import Model
from mbjax._src.rigid.frames import frame_placement
from mbjax._src.system.system import AbstractSystem
from mbjax._src.trajopt.costs import as_cost
from mbjax._src.trajopt.residuals import given_forces, knot_forces, reads_forces


class AbstractKnot(eqx.Module):
    """One knot of a `Problem`: how the state moves on to the next knot, and the
    running cost there."""

    running: eqx.AbstractVar[Callable]

    @abc.abstractmethod
    def advance(self, integrator, t, q: Array, v: Array, u: Array,
                dt) -> tuple[Array, Array, Array | None]:
        """(q, v) at the next knot from (q, v) at time t under the control u, and the forces
        that the step solved which the knot's costs read (None where they read none)."""

    def transition(self, integrator, t, q: Array, v: Array, u: Array, dt) -> tuple[Array, Array]:
        """(q, v) at the next knot from (q, v) at time t under the control u."""
        return self.advance(integrator, t, q, v, u, dt)[:2]

    def cost(self, t, q: Array, v: Array, u: Array, forces: Array | None = None) -> Array:
        """The running cost at (q, v, u), time t: a scalar or residuals.

        Args:
            t: the knot's time [s].
            q: configuration, shape (nq,).
            v: velocity, shape (nv,).
            u: control, shape (nu,).
            forces: the forces from `advance` at the same (t, q, v, u), or None to solve them
                where the costs read them.
        """
        return self.running(q, v, u)

    def wrenches(self, t, q: Array, v: Array, u: Array) -> Array | None:
        """The ground's wrench on each contact of the knot's stance at (t, q, v, u), as
        `mbjax.contact.contact_wrenches` gives them; None where the knot holds no stance."""
        return None

    @abc.abstractmethod
    def duration(self, dt: float) -> float:
        """The time from this knot to the next: dt for a step, none for an impulse."""

    @abc.abstractmethod
    def weight(self, dt: float) -> float:
        """The running cost's weight: dt where the cost is a rate (a step), 1 where it is taken
        as it is (an impulse, which takes no time)."""

    def jumps(self) -> bool:
        """Whether the state jumps by design at this knot (an impulse: the velocity changes in no
        time)."""
        return False

    @abc.abstractmethod
    def controlled(self) -> AbstractSystem | None:
        """The system whose control the knot's u is; None where u moves nothing (an
        impulse)."""

    @abc.abstractmethod
    def quasi_static_control(self, q: Array, nu: int) -> Array:
        """The control u, shape (nu,), that holds the configuration q at rest (`quasi_static`);
        the least-squares answer where none can."""

    def kind(self) -> tuple:
        """What two knots share to look alike to a reader, their class and what they step: two
        alike knots that make different phases get a warning naming why (`Schedule`)."""
        return (type(self),)

    def vectorizable(self) -> bool:
        """Whether a phase of such knots may be `vmap`ped over its knots (`Schedule.map`): not
        where its step factorizes matrices (a stance's or an impulse's contact solve), whose
        batched LAPACK calls can deadlock XLA's CPU thread pool."""
        return False


class Knot(AbstractKnot):
    """A step of a system under a control held over it: a knot of a contact phase (its
    `mbjax.contact.stance`), of a flight, or of any system.

    The contact residuals (`friction_cone_residual`, ...) made from the knot's own stance (that
    very object) read the forces that the knot's step solves: the stance is solved once per
    knot, for the step and its costs alike (Crocoddyl's shared contact data).

    Args:
        system: the system stepped (its control is the problem's unknown u_k).
        running: the cost rate running(q, v, u) at this knot, a scalar or residuals, or a
            tuple of such functions (as `Problem`'s running).
    """

    system: AbstractSystem
    running: Callable

    def __init__(self, system: AbstractSystem, running: Callable):
        if not isinstance(system, AbstractSystem):
            raise TypeError(f"system must be an mbjax system (TreeSystem, stance(...), ...), got "
                            f"{type(system).__name__}")
        self.system = system
        self.running = knot_forces(as_cost(running, "running(q, v, u)"), system)

    def _held(self, t, q, v, u) -> AbstractSystem:
        return self.system.with_control(Constant(u)).hold(t, q, v)

    def advance(self, integrator, t, q, v, u, dt):
        system = self._held(t, q, v, u)
        a0 = forces = None
        if reads_forces(self.running):          # one solve for the step and the costs
            a0, multipliers = system.solve(t, q, v)
            forces = stance_wrenches(system, q, multipliers)
        q1, v1, _ = integrator.advance(system, t, q, v, dt, a0=a0)     # held already: as is
        return q1, v1, forces

    def cost(self, t, q, v, u, forces=None):
        if not reads_forces(self.running):
            return self.running(q, v, u)
        if forces is None:
            forces = self.wrenches(t, q, v, u)
        return given_forces(self.running, forces)(q, v, u)

    def wrenches(self, t, q, v, u):
        if not is_stance(self.system):
            return None
        return contact_wrenches(self._held(t, q, v, u), t, q, v)

    def vectorizable(self) -> bool:
        """A step of a system without contacts is vectorized over the phase's knots."""
        return not is_stance(self.system)

    def duration(self, dt):
        return dt

    def weight(self, dt):
        return dt

    def controlled(self):
        return self.system

    def kind(self):
        return (type(self), type(self.system))

    def quasi_static_control(self, q, nu):
        """The control that holds q at rest in the knot's system (`holding_control`: a stance's
        feet help hold it)."""
        return self.system.holding_control(q, nu)


class Impulse(AbstractKnot):
    """A touchdown: the contacts that start stop their frames at once (`mbjax.contact.impulse`),
    in no time, and the control is idle (Crocoddyl's `ActionModelImpulseFwdDynamics`).

    Args:
        model: the robot.
        contacts: the contacts whose frames the impulse stops (Crocoddyl's examples pass the
            feet that land).
        running: the cost running(q, v, u) at the impulse's knot, taken as it is (not a rate:
            the impulse takes no time); u is the problem's control there, which moves nothing.
    """

    model: Model
    contacts: tuple
    running: Callable

    def __init__(self, model: Model, contacts: Sequence[AbstractContact], running: Callable):
        if not isinstance(model, Model):
            raise TypeError(f"model must be a mbjax.Model, got {type(model).__name__}")
        self.model, self.contacts, self.running = model, tuple(contacts), as_cost(running, "running(q, v, u)")
        for c in self.contacts:
            if not isinstance(c, AbstractContact):
                raise TypeError(f"contacts must be PointContact(...) or SurfaceContact(...), got "
                                f"{c!r}")
            frame_placement(model, c.frame)          # a KeyError names a frame the model lacks

    def advance(self, integrator, t, q, v, u, dt):
        return q, impulse_map(self.model, q, v, self.contacts)[0], None

    def duration(self, dt):
        return 0.0

    def weight(self, dt):
        return 1.0

    def jumps(self):
        return True

    def controlled(self):
        return None

    def quasi_static_control(self, q, nu):
        """Zero: the impulse's control moves nothing."""
        return jnp.zeros(nu, q.dtype)


class Schedule(eqx.Module):
    """A sequence of knots grouped into phases: knots alike but for their arrays (a stance's
    anchors, a cost's targets) make one phase, whose arrays are stacked along a first axis, so
    a solver compiles each phase's step and expansion once and runs it over the phase's knots.

    Args:
        knots: one `AbstractKnot` per step.
        dt: the problem's step, for each knot's time.

    Raises:
        TypeError: an entry that is not a knot.
        ValueError: no knots, or knots with different numbers of controls.

    Warns:
        UserWarning: two consecutive knots alike (`AbstractKnot.kind`: a class, a system's type)
            that make different phases, naming the knots and the first difference found (a cost
            missing, a different number of contacts): each phase compiles on its own.
    """

    templates: tuple = eqx.field(static=True)   # each phase's knots without their arrays
    arrays: tuple                               # each phase's knots' arrays, stacked
    axes: tuple = eqx.field(static=True)        # 0 for a stacked array, None for a shared one
    phase: tuple = eqx.field(static=True)       # each knot's phase
    index: tuple = eqx.field(static=True)       # each knot's place in its phase
    times: tuple = eqx.field(static=True)       # each knot's time, from the step dt

    def __init__(self, knots: Sequence[AbstractKnot], dt: float):
        knots = tuple(knots)
        if not knots:
            raise ValueError("knots must hold one knot per step, got none")
        for i, knot in enumerate(knots):
            if not isinstance(knot, AbstractKnot):
                raise TypeError(f"knots[{i}] must be a Knot(...) or an Impulse(...), got "
                                f"{type(knot).__name__}")
        templates, members, phase, index, steps = [], [], [], [], []
        previous = None
        for knot in knots:
            if knot is not previous:         # a knot repeated (a one-system problem's) is read once
                duration = knot.duration(1.0)            # in steps dt
                arrays, template = eqx.partition(knot, eqx.is_array)
                shapes = jax.tree.map(lambda a: (a.shape, a.dtype), arrays)
                for p, (other, other_shapes) in enumerate(templates):
                    if _same(other, template) and other_shapes == shapes:
                        break
                else:
                    p = len(templates)
                    templates.append((template, shapes))
                    members.append([])
                previous = knot
            phase.append(p)
            index.append(len(members[p]))
            members[p].append(arrays)
            steps.append(duration)
        self.templates = tuple(t for t, _ in templates)
        self.axes, self.arrays = zip(*(_stacked(m) for m in members), strict=True)
        self.phase, self.index = tuple(phase), tuple(index)
        # a knot's time is its count of steps times dt, as k dt exactly
        self.times = tuple(float(n * dt) for n in np.cumsum([0.0] + steps)[:-1])
        for i in range(1, len(knots)):
            if phase[i] != phase[i - 1] and knots[i].kind() == knots[i - 1].kind():
                warnings.warn(
                    f"knots[{i - 1}] and knots[{i}] are alike ({type(knots[i]).__name__}s of the "
                    f"same kind) but make different phases, each compiled on its own: "
                    f"{_difference(knots[i - 1], knots[i], 'knot') or 'their structure differs'}"
                    f"; write alike knots over the same contacts and costs (those not in use "
                    f"inactive or weighted 0) so that they share a phase",
                    stacklevel=_caller_level())

    @property
    def n_phases(self) -> int:
        """The number of distinct phases, each compiled once."""
        return len(self.templates)

    def knot(self, p: int, j) -> AbstractKnot:
        """The j-th knot of phase p (j may be traced)."""
        arrays = jax.tree.map(lambda axis, a: a if axis is None else a[j], self.axes[p],
                              self.arrays[p], is_leaf=_none)
        return eqx.combine(arrays, self.templates[p])

    def members(self, p: int) -> np.ndarray:
        """The knots of phase p, in order."""
        return np.flatnonzero(np.asarray(self.phase) == p)

    def switch(self, k, fn: Callable, *args):
        """fn(knot k, *args) for a traced knot index k: one branch per phase."""
        phase, index = jnp.asarray(self.phase)[k], jnp.asarray(self.index)[k]
        branches = [lambda j, *a, p=p: fn(self.knot(p, j), *a) for p in range(len(self.templates))]
        if len(branches) == 1:
            return branches[0](index, *args)
        return jax.lax.switch(phase, branches, index, *args)

    def map(self, fn: Callable, *args):
        """fn(knot k, *args[k]) for every knot k, over each phase's knots: each phase compiles
        once. args are arrays with a first axis of one entry per knot.

        A loop (`lax.map`) over a phase of stances or impulses, not a `vmap`: vmapped over
        knots, a stance's Cholesky factors and solves become batched LAPACK calls, which jaxlib
        0.10.2 splits over XLA's CPU thread pool and waits for; two at once on a two-thread pool
        wait for each other forever (the ANYmal walk's iterations hung so). The loop also
        compiles faster (benchmarks/README.md). A phase of knots without contacts
        (`AbstractKnot.vectorizable`) is vmapped."""
        outs, order = [], []
        for p, template in enumerate(self.templates):
            ks = self.members(p)
            shared, stacked = _split(self.arrays[p], self.axes[p])

            def one(xs, t=template, shared=shared):
                return fn(eqx.combine(shared, xs[0], t), *xs[1:])
            inputs = (stacked, *(args if len(self.templates) == 1 else (a[ks] for a in args)))
            outs.append(jax.vmap(one)(inputs) if template.vectorizable()
                        else jax.lax.map(one, inputs))
            order.append(ks)
        if len(outs) == 1:
            return outs[0]
        inverse = np.argsort(np.concatenate(order))
        return jax.tree.map(lambda *o: jnp.concatenate(o)[inverse], *outs)


def _caller_level() -> int:
    """The `warnings.warn` stacklevel of the first caller outside mbjax and equinox (whose
    module constructors wrap `__init__`), so that a warning names the user's line."""
    inside = tuple(str(folder) + os.sep for folder in (Path(__file__).parents[2],
                                                       Path(eqx.__file__).parent))
    frame, level = sys._getframe(1), 1
    while frame is not None and frame.f_code.co_filename.startswith(inside):
        frame, level = frame.f_back, level + 1
    return level


def _stacked(members: list) -> tuple:
    """(axes, arrays) of a phase's knots' arrays: an array every knot holds (the model, a
    weight) kept once (axis None), the others stacked along a first axis (0)."""
    if all(a is members[0] for a in members):      # one knot repeated
        return jax.tree.map(lambda _: None, members[0]), members[0]
    axes = jax.tree.map(lambda *a: None if all(x is a[0] for x in a) else 0, *members)
    return axes, jax.tree.map(lambda axis, *a: a[0] if axis is None else jnp.stack(a), axes,
                              *members, is_leaf=_none)


def _split(arrays, axes):
    """(shared, stacked): a phase's arrays kept once, and those stacked along a first axis."""
    shared = jax.tree.map(lambda axis, a: a if axis is None else None, axes, arrays, is_leaf=_none)
    stacked = jax.tree.map(lambda axis, a: None if axis is None else a, axes, arrays, is_leaf=_none)
    return shared, stacked


def _none(x) -> bool:
    return x is None


def _same(a, b) -> bool:
    """Whether two knots stripped of their arrays are the same phase: the same tree structure
    (with the static fields of their modules) and the same other leaves (`_equal`)."""
    if jax.tree.structure(a) != jax.tree.structure(b):
        return False
    return all(_equal(x, y) for x, y in zip(jax.tree.leaves(a), jax.tree.leaves(b), strict=True))


# leaves compared by value; any other leaf (a function, a callable object) is the same only if it
# is that very object, as a function's == is
_VALUES = (bool, int, float, complex, str, bytes, type(None), np.dtype, slice, enum.Enum)


def _equal(x, y) -> bool:
    """Whether two leaves of knots stripped of their arrays are the same."""
    if x is y:
        return True
    return type(x) is type(y) and isinstance(x, _VALUES) and bool(x == y)


def _difference(a, b, path: str) -> str:
    """The first difference found between two knots (or their parts at `path`) that keeps them
    out of one phase, in words."""
    if type(a) is not type(b):
        return f"{path} is of type {type(a).__name__} in one, {type(b).__name__} in the other"
    if isinstance(a, eqx.Module):
        for field in dataclasses.fields(a):
            found = _difference(getattr(a, field.name), getattr(b, field.name),
                                f"{path}.{field.name}")
            if found:
                return found
        return ""
    if isinstance(a, list | tuple):
        if len(a) != len(b):
            return f"{path} has {len(a)} entries in one, {len(b)} in the other"
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            found = _difference(x, y, f"{path}[{i}]")
            if found:
                return found
        return ""
    if isinstance(a, dict):
        if a.keys() != b.keys():
            return f"{path} has keys {sorted(map(str, a))} in one, {sorted(map(str, b))} in the other"
        for key in a:
            found = _difference(a[key], b[key], f"{path}[{key!r}]")
            if found:
                return found
        return ""
    if eqx.is_array(a):
        if (np.shape(a), a.dtype) != (np.shape(b), b.dtype):
            return (f"{path} has shape {np.shape(a)} {a.dtype} in one, {np.shape(b)} {b.dtype} in "
                    f"the other")
        return ""
    if jax.tree.structure(a) != jax.tree.structure(b):
        return f"{path} differs in structure"
    if not all(_equal(x, y) for x, y in zip(jax.tree.leaves(a), jax.tree.leaves(b), strict=True)):
        return f"{path} differs ({_short(a)} in one, {_short(b)} in the other)"
    return ""


def _short(x) -> str:
    text = repr(x)
    return text if len(text) <= 60 else text[:57] + "..."
