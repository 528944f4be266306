"""`FlexibleModel`: a tree of rigid and modal flexible bodies (Anderson 1993 §2.1, Figs. 1-2).

The tree, its joints and placements and the rigid bodies' inertia are a `mbjax.model.Model`;
the flexible bodies are `ModalBody`s that replace the inertia of theirs. A flexible body's frame is
its joint grid J^k (the modes are clamped there, `mbjax._src.flex.modal`); a body hanging from a
flexible body is attached at one of its parent's grid points (`attach`), whose translation
phi_h q and rotation exp(psi_h q) carry the child's joint (eqs 5-8, 20-23). Cut joints of
`mbjax.loops` reach grid points of flexible bodies through `markers`.

Coordinates: q = (joint coordinates of the rigid model, modal coordinates of the flexible bodies
in body order), v likewise (u^{B^k} = q_dot^{B^k}, eq 19). Per body the modal coordinates are
padded to the largest count mu, so every body is a (6 + mu)-block of one stacked `ModalBody`.
"""

import warnings
from functools import cached_property

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jax import Array

from mbjax._src.flex.body import ModalBody
from mbjax._src.model import Model


class FlexibleModel(eqx.Module):
    """A rigid `model` with some bodies made flexible.

    q = (the rigid model's joint coordinates, the flexible bodies' modal coordinates in body
    order), v likewise (u^{B^k} = q_dot^{B^k}, Anderson 1993 eq 19). Per body the modal
    coordinates are padded to the largest count mu, so every body is a (6 + mu)-block of one
    stacked `ModalBody`. A flexible body's mass, centre of mass and
    inertia are its ModalBody's (its rigid-body terms); the rigid `model`'s values for that body
    are not used. A rigid part that moves with the body (a hub at the clamp) goes into the
    ModalBody (`rotary`, as `mbjax.scenes.slewing_beam` does); a rigid mass that differs
    from the ModalBody's by more than `MASS_MISMATCH` (relative) gets a warning, so that such a
    part is not dropped unseen.

    Args:
        model: the tree, its joints, placements and rigid bodies' inertia (a `mbjax.Model`).
        flexible: {body index: `ModalBody`} for the bodies made flexible (at least one, with
            at least one mode).
        attach: {child body: attachment-point index of its flexible parent's ModalBody} for
            every child of a flexible body.
        markers (Sequence[tuple[int, int]]): extra frames for cut joints and loads, ((body, point),
            ...): frame index n + i is marker i, at attachment point `point` of flexible body
            `body`, or at the body's own frame with point -1.

    Raises:
        TypeError: `model` not a `mbjax.Model`, or a flexible entry not a `ModalBody`.
        ValueError: no flexible body or no modes, a body or attachment point that does not
            exist, a child of a flexible body without `attach`, or an `attach` for a child of a
            rigid body.

    The tree (Anderson 1993 §2.1, Figs. 1-2):
        The tree, its joints and placements and the rigid bodies' inertia are a
        `mbjax.model.Model`; the flexible bodies are `ModalBody`s that replace the inertia of
        theirs. A flexible body's frame is its joint grid J^k (the modes are clamped there, as
        `mbjax.flex.craig_bampton` builds them); a body hanging from a flexible body is attached
        at one of its parent's grid points (`attach`), whose translation phi_h q and rotation
        exp(psi_h q) carry the child's joint (eqs 5-8, 20-23). Cut joints of `mbjax.loops`
        reach grid points of flexible bodies through `markers`.
    """

    model: Model
    bodies: ModalBody                                   # stacked, leading axis n, padded to mu
    modes: tuple[int, ...] = eqx.field(static=True)     # modal coordinates per body (0: rigid)
    attach: tuple[int, ...] = eqx.field(static=True)    # grid point on the parent, -1: none
    markers: tuple[tuple[int, int], ...] = eqx.field(static=True)

    def __init__(self, model: Model, flexible: dict, attach: dict | None = None, markers=()):
        if not isinstance(model, Model):
            raise TypeError(f"model must be a mbjax.model.Model, got {type(model).__name__}")
        n = model.n
        attach = dict(attach or {})
        for k, body in flexible.items():
            if not isinstance(body, ModalBody):
                raise TypeError(f"flexible[{k}] must be a ModalBody, got {type(body).__name__}")
            if not 0 <= k < n:
                raise ValueError(f"flexible body {k} is not in the model (0 ... {n - 1})")
        if not flexible:
            raise ValueError("no flexible body: use the rigid Model and mbjax.forward_dynamics")
        mu = max(b.mu for b in flexible.values())
        if mu < 1:
            raise ValueError("the flexible bodies have no modal coordinates")
        nodes = max(max(b.node_position.shape[0] for b in flexible.values()), 1)
        parents = model.topology.parents
        for k in range(n):
            parent = parents[k]
            if parent in flexible:
                if k not in attach:
                    raise ValueError(f"body {k} hangs from flexible body {parent}: give the grid "
                                     f"point it is attached at, attach={{{k}: node}}")
                if not 0 <= attach[k] < flexible[parent].node_position.shape[0]:
                    raise ValueError(f"body {k} is attached at grid point {attach[k]} of body "
                                     f"{parent}, which has "
                                     f"{flexible[parent].node_position.shape[0]} attachment points")
            elif k in attach:
                raise ValueError(f"attach[{k}]: body {k}'s parent {parent} is not flexible")
        markers = tuple((int(b), int(h)) for b, h in markers)
        for b, h in markers:
            if not 0 <= b < n:
                raise ValueError(f"marker on body {b}: not in the model (0 ... {n - 1})")
            if h >= 0 and (b not in flexible or h >= flexible[b].node_position.shape[0]):
                raise ValueError(f"marker ({b}, {h}): body {b} has no attachment point {h}")
        _warn_on_replaced_mass(model, flexible)
        stacked = [flexible[k].padded(mu, nodes) if k in flexible
                   else ModalBody.rigid(model.mass[k], model.com[k], model.inertia[k], mu)
                   .padded(mu, nodes) for k in range(n)]
        self.model = model
        self.bodies = _stack(*stacked)
        self.modes = tuple(flexible[k].mu if k in flexible else 0 for k in range(n))
        self.attach = tuple(attach.get(k, -1) for k in range(n))
        self.markers = markers

    # -- sizes and layout -----------------------------------------------------------------------

    @property
    def n(self) -> int:
        """Number of bodies."""
        return self.model.n

    @property
    def mu(self) -> int:
        """Modal columns per body (the padded width)."""
        return self.bodies.modal_mass.shape[-1]

    @property
    def n_modal(self) -> int:
        """Number of modal coordinates, over all bodies (unpadded)."""
        return sum(self.modes)

    @property
    def nq(self) -> int:
        """Number of configuration coordinates: joint, then modal."""
        return self.model.nq + self.n_modal

    @property
    def nv(self) -> int:
        """Number of velocity coordinates: joint, then modal."""
        return self.model.nv + self.n_modal

    @property
    def n_frames(self) -> int:
        """Bodies plus markers: the frames cut joints can use."""
        return self.n + len(self.markers)

    @cached_property
    def _modal_index(self) -> tuple[np.ndarray, np.ndarray]:
        starts = np.cumsum([0, *self.modes])
        index = np.array([[min(starts[k] + j, max(starts[-1] - 1, 0)) for j in range(self.mu)]
                          for k in range(self.n)])
        mask = np.array([[j < self.modes[k] for j in range(self.mu)] for k in range(self.n)])
        return index, mask

    def split(self, x: Array) -> tuple[Array, Array]:
        """The joint part and the per-body modal part of a q or v vector.

        Args:
            x: a q vector, shape (nq,), or a v vector, shape (nv,).

        Returns:
            (joint part, modal part), the modal part per body zero-padded, shape (n, mu).
        """
        index, mask = self._modal_index
        joint, modal = x[:-self.n_modal], x[-self.n_modal:]
        return joint, jnp.where(mask, modal[index], 0.0)

    def join(self, joint: Array, modal: Array) -> Array:
        """Inverse of split: (joint part, (n, mu) modal part) -> flat vector."""
        return jnp.concatenate([joint, modal[self._modal_index[1]]])

    def modal_slice(self, body: int) -> slice:
        """Where body's modal coordinates sit in q (in v they sit model.nq - model.nv places
        earlier: the same place where every joint coordinate is its own rate).

        Args:
            body: a body index.

        Returns:
            The slice of q holding that body's modal coordinates (empty for a rigid body).
        """
        start = self.model.nq + sum(self.modes[:body])
        return slice(start, start + self.modes[body])

    def neutral(self) -> Array:
        """The reference configuration, shape (nq,): the rigid model's, undeformed."""
        return jnp.concatenate([self.model.neutral(), jnp.zeros(self.n_modal)])

    # -- the coordinates' kinematics (modal coordinates are Euclidean, eq 19) --------------------

    def q_dot(self, q: Array, v: Array) -> Array:
        """dq/dt, shape (nq,), for velocity v (nv,): the rigid model's, and u for the modes."""
        nq, nv = self.model.nq, self.model.nv
        return jnp.concatenate([self.model.q_dot(q[:nq], v[:nv]), v[nv:]])

    def retract(self, q0: Array, xi: Array) -> Array:
        """The configuration at chart point xi (nv,) about q0 (nq,): the rigid model's chart,
        q0 + xi for the modes."""
        nq, nv = self.model.nq, self.model.nv
        return jnp.concatenate([self.model.retract(q0[:nq], xi[:nv]), q0[nq:] + xi[nv:]])

    def difference(self, q0: Array, q1: Array, *, wrap: bool = True) -> Array:
        """The chart point xi (nv,) about q0 at which `retract` gives q1: the rigid model's
        difference (`Model.difference`, continuous joints wrapped with `wrap`), q1 - q0 for
        the modes."""
        nq = self.model.nq
        return jnp.concatenate([self.model.difference(q0[:nq], q1[:nq], wrap=wrap),
                                q1[nq:] - q0[nq:]])

    def local_rate(self, q0: Array, xi: Array, v: Array) -> Array:
        """xi_dot, shape (nv,), at chart point xi about q0 for velocity v."""
        nq, nv = self.model.nq, self.model.nv
        return jnp.concatenate([self.model.local_rate(q0[:nq], xi[:nv], v[:nv]), v[nv:]])

    def normalize(self, q: Array) -> Array:
        """q, shape (nq,), with every quaternion scaled to unit length."""
        nq = self.model.nq
        return jnp.concatenate([self.model.normalize(q[:nq]), q[nq:]])

    def without_stiffening(self) -> "FlexibleModel":
        """Geometric stiffening switched off in every body."""
        return eqx.tree_at(lambda m: m.bodies, self, self.bodies.without_stiffening())


# how far (relative) a flexible body's rigid mass may be from its ModalBody's before a warning
MASS_MISMATCH = 0.01


def _warn_on_replaced_mass(model: Model, flexible: dict) -> None:
    """Warn where the rigid model gives a flexible body a mass its ModalBody does not have
    (concrete values only: under a trace there is nothing to compare)."""
    for k, body in flexible.items():
        try:
            rigid, modal = float(model.mass[k]), float(body.mass)
        except (jax.errors.ConcretizationTypeError, TypeError):
            continue
        if abs(rigid - modal) > MASS_MISMATCH * abs(modal):
            warnings.warn(f"FlexibleModel: body {k}'s mass in the rigid model, {rigid:g}, is "
                          f"not used: its ModalBody's, {modal:g}, replaces it (with its centre "
                          "of mass and inertia); put a rigid part that moves with the body into "
                          "the ModalBody", stacklevel=4)


@eqx.filter_jit
def _stack(*bodies: ModalBody) -> ModalBody:
    """The bodies' coefficients stacked along a new leading axis (one compiled program)."""
    return jax.tree.map(lambda *a: jnp.stack(a), *bodies)
