"""Residuals for the common costs of Crocoddyl's examples, as cost functions for a `Problem`.

Each helper returns an equinox module r(q, v, u) (u optional, so one serves as a running and a
terminal cost) giving a vector of residuals, which `Problem` reads as the cost 1/2 |r|^2 and
expands by Gauss-Newton. A weight w (a scalar, or one per residual component) scales the residual
by sqrt(w), so that the cost is w 1/2 |r|^2: Crocoddyl's `CostModelResidual` with its weight and a
quadratic (`ActivationModelQuad`) or weighted quadratic (`ActivationModelWeightedQuad`)
activation. Being modules, their targets and weights are leaves: a problem with another target
reuses the compiled solve. A tuple of them is their sum (`Problem`'s running and terminal).

The contact residuals read a stance's forces: in a `Knot` of the stance they were made from,
the forces that the knot's step solved (Crocoddyl's shared contact data), so a knot solves its
stance once; called on their own, they solve it.
"""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jax import Array

from mbjax._src.contact.friction import cone_rows, friction, ground_frame, wrench_cone_rows
from mbjax._src.contact.stance import contact_wrenches, stance_contacts
from mbjax._src.control import Constant
from mbjax._src.lie import gamma_inv, log
from mbjax._src.lie.inputs import check_point
from mbjax._src.model.model import Model
from mbjax._src.rigid.centre import center_of_mass
from mbjax._src.rigid.frames import frame_pose
from mbjax._src.system.system import AbstractSystem


def _root(weight) -> Array:
    weight = jnp.asarray(weight, dtype=float)
    return jnp.sqrt(weight)


class _State(eqx.Module):
    space: eqx.Module
    q_ref: Array
    v_ref: Array
    root: Array

    def __call__(self, q: Array, v: Array, u: Array | None = None) -> Array:
        return self.root * jnp.concatenate([self.space.difference(self.q_ref, q), v - self.v_ref])


class _Frame(eqx.Module):
    model: eqx.Module
    frame: str = eqx.field(static=True)
    translation: Array | None
    rotation: Array | None
    root: Array

    def __call__(self, q: Array, v: Array, u: Array | None = None) -> Array:
        R, p = frame_pose(self.model, q, self.frame)
        if self.rotation is None:
            return self.root * (p - self.translation)
        omega = log(self.rotation.T @ R, check=False)
        if self.translation is None:
            return self.root * omega
        return self.root * jnp.concatenate(
            [omega, gamma_inv(omega) @ (self.rotation.T @ (p - self.translation))])


class _Control(eqx.Module):
    u_ref: Array
    root: Array

    def __call__(self, q: Array, v: Array, u: Array) -> Array:
        return self.root * (u - self.u_ref)


def state_residual(space, q_ref, v_ref=None, weight=1.0) -> eqx.Module:
    """State regularisation: r = sqrt(w) (difference(q_ref, q); v - v_ref).

    The configuration's deviation is measured on its manifold (`Model.difference`: a continuous
    joint's angle wrapped to [-pi, pi), a free joint's SE(3) logarithm), as Crocoddyl's
    `ResidualModelState`.

    Args:
        space (Model | AbstractSystem): what measures the configuration's deviation: a `mbjax.Model`
            (its `difference`, continuous joints wrapped) or a system (its chart's `difference`,
            angles counting turns).
        q_ref (Array): the reference configuration, shape (nq,).
        v_ref (Array | None): the reference velocity, shape (nv,); zeros by default.
        weight (float | Array): w, a scalar or one per residual (nv + nv entries: the tangent of q,
            then v).

    Returns:
        The residual function r(q, v, u=None), shape (2 nv,) for a tree.

    Raises:
        TypeError: space is neither a Model nor a system.
    """
    if not isinstance(space, Model | AbstractSystem):
        raise TypeError(f"space must be a Model or a system with `difference`, got "
                        f"{type(space).__name__}")
    q_ref = jnp.asarray(q_ref, dtype=float)
    nv = space.difference(q_ref, q_ref).shape[0]
    v_ref = jnp.zeros(nv) if v_ref is None else jnp.asarray(v_ref, dtype=float)
    return _State(space, q_ref, v_ref, _root(weight))


def frame_residual(model, frame: str, translation=None, rotation=None,
                   weight=1.0) -> eqx.Module:
    """A frame's placement, position or orientation against a target.

    With both targets, the SE(3) logarithm of the target's inverse times the frame's pose,
    r = sqrt(w) (omega; Gamma(omega)^-1 R_ref^T (p - p_ref)) with omega = log(R_ref^T R)
    (Crocoddyl's `ResidualModelFramePlacement`, in mbjax's (angular; linear) order); with a
    translation only, r = sqrt(w) (p - p_ref) (`ResidualModelFrameTranslation`); with a rotation
    only, r = sqrt(w) omega (`ResidualModelFrameRotation`).

    Args:
        model (Model): the `mbjax.Model`.
        frame: the frame's, body's or joint's name (`mbjax.rigid.frame_pose`).
        translation (Array | None): the target origin in the world [m], shape (3,); None for a
            rotation residual.
        rotation (Array | None): the target orientation (frame to world), shape (3, 3); None for a
            translation residual.
        weight (float | Array): w, a scalar or one per residual (6 or 3).

    Returns:
        The residual function r(q, v, u=None), shape (6,) or (3,).

    Raises:
        KeyError: no frame of that name.
        ValueError: neither a translation nor a rotation.
    """
    if translation is None and rotation is None:
        raise ValueError("frame_residual needs a target translation, rotation or both")
    frame_pose(model, model.neutral(), frame)                   # a KeyError names the frame
    translation, rotation = (None if x is None else jnp.asarray(x, dtype=float)
                             for x in (translation, rotation))
    return _Frame(model, frame, translation, rotation, _root(weight))


def control_residual(nu: int, u_ref=None, weight=1.0) -> eqx.Module:
    """Control regularisation: r = sqrt(w) (u - u_ref) (Crocoddyl's `ResidualModelControl`).

    Args:
        nu: the number of controls.
        u_ref (Array | None): the reference control, shape (nu,); zeros by default (a
            gravity-holding torque is a common choice).
        weight (float | Array): w, a scalar or one per control.

    Returns:
        The residual function r(q, v, u), shape (nu,).
    """
    u_ref = jnp.zeros(nu) if u_ref is None else jnp.asarray(u_ref, dtype=float)
    return _Control(u_ref, _root(weight))


class _CoM(eqx.Module):
    model: eqx.Module
    target: Array
    root: Array

    def __call__(self, q: Array, v: Array, u: Array | None = None) -> Array:
        return self.root * (center_of_mass(self.model, q) - self.target)


def com_residual(model, target, weight=1.0) -> eqx.Module:
    """The centre of mass against a target: r = sqrt(w) (c(q) - c_ref) (Crocoddyl's
    `ResidualModelCoMPosition`).

    Args:
        model (Model): the `mbjax.Model`.
        target (Array): the target position in the world [m], shape (3,).
        weight (float | Array): w, a scalar or one per component.

    Returns:
        The residual function r(q, v, u=None), shape (3,).
    """
    return _CoM(model, check_point(target, "target", "the centre of mass's target"),
                _root(weight))


class _Forces(eqx.Module):
    """The ground's wrench on each of a stance's contacts at (q, v, u), world components:
    solved from `phase`, or, in a knot of that phase (phase None), the wrenches its step solved
    (`given`, bound by `Knot.cost`)."""

    phase: eqx.Module | None
    given: Array | None = None

    def __call__(self, q: Array, v: Array, u: Array) -> Array:
        if self.given is not None:
            return self.given
        if self.phase is None:
            raise ValueError("this contact residual reads the forces of its knot's step: "
                             "evaluate it through its Knot (Knot.cost)")
        system = self.phase.with_control(Constant(u)).hold(0.0, q, v)
        return contact_wrenches(system, 0.0, q, v)


def _is_forces(x) -> bool:
    return isinstance(x, _Forces)


def knot_forces(cost, phase):
    """`cost` with each contact residual made from `phase` (that very object) reading the
    forces that a knot of `phase` computes in its step (Crocoddyl's shared contact data)."""
    return jax.tree.map(lambda f: _Forces(None) if _is_forces(f) and f.phase is phase else f,
                        cost, is_leaf=_is_forces)


def reads_forces(cost) -> bool:
    """Whether a cost holds contact residuals that read their knot's forces (`knot_forces`)."""
    return any(_is_forces(f) and f.phase is None and f.given is None
               for f in jax.tree.leaves(cost, is_leaf=_is_forces))


def given_forces(cost, wrenches: Array):
    """`cost` with the contact residuals that read their knot's forces given `wrenches`, shape
    (number of contacts, 6)."""
    return jax.tree.map(lambda f: _Forces(None, wrenches) if _is_forces(f) and f.phase is None
                        else f, cost, is_leaf=_is_forces)


class _Cone(eqx.Module):
    forces: _Forces
    A: Array                       # facets' rows, then the normal's, per contact
    root: Array

    def __call__(self, q: Array, v: Array, u: Array) -> Array:
        r = jnp.einsum("kij,kj->ki", self.A, self.forces(q, v, u)[:, 3:])
        # Crocoddyl's quadratic barrier: the facets' rows above 0, the normal's below 0
        return self.root * jnp.concatenate([jnp.maximum(r[:, :-1], 0.0),
                                            jnp.minimum(r[:, -1:], 0.0)], axis=1).ravel()


def friction_cone_residual(phase, mu=0.7, facets: int = 4, weight=1.0) -> eqx.Module:
    """Each point contact's force outside its linearised friction cone, with a bounded
    activation: zero inside (Crocoddyl's `ResidualModelContactFrictionCone` with
    `ActivationModelQuadraticBarrier`, its gait examples' cost).

    The cone of a contact of normal n, tangents t_i at angles 2 pi i / facets about n (the
    world's x and y first for n = z), bounds the force f by the facets (t_i - mu n) . f <= 0 and
    n . f >= 0; the residual is each row's excess, sqrt(w) max((t_i - mu n) . f, 0) and
    sqrt(w) min(n . f, 0), so that 1/2 |r|^2 is zero wherever the contact holds without slipping
    or pulling.

    Args:
        phase: the stance, as `mbjax.contact.stance` made it: its contacts are coned (point
            contacts; a surface contact's force alike).
        mu: the friction coefficient, positive.
        facets: the cone's facets (static).
        weight (float | Array): w.

    Returns:
        The residual function r(q, v, u), shape (len(contacts) (facets + 1),).

    Raises:
        ValueError: mu is not positive, facets < 3, or the phase is not a stance.
    """
    mu = friction(mu)
    if int(facets) < 3:
        raise ValueError(f"facets must be at least 3, got {facets!r}")
    contacts = stance_contacts(phase)
    A = jnp.stack([cone_rows(c.normal, mu, int(facets)) for c in contacts])
    return _Cone(_Forces(phase), A, _root(weight))


class _Force(eqx.Module):
    forces: _Forces
    reference: Array
    root: Array

    def __call__(self, q: Array, v: Array, u: Array) -> Array:
        return self.root * (self.forces(q, v, u) - self.reference).ravel()


def contact_force_residual(phase, reference=None, weight=1.0) -> eqx.Module:
    """The contacts' wrenches against a reference (Crocoddyl's `ResidualModelContactForce`):
    r = sqrt(w) (w_c - w_ref), each contact's (torque; force) in world components at its frame
    (`mbjax.contact.contact_wrenches`).

    Args:
        phase: the stance, as `mbjax.contact.stance` made it.
        reference (Array | None): the reference wrenches, shape (len(contacts), 6); zeros by
            default.
        weight (float | Array): w, a scalar or one per residual.

    Returns:
        The residual function r(q, v, u), shape (6 len(contacts),).

    Raises:
        ValueError: the phase is not a stance, or a reference of the wrong shape.
    """
    contacts = stance_contacts(phase)
    shape = (len(contacts), 6)
    reference = jnp.zeros(shape) if reference is None else jnp.asarray(reference, dtype=float)
    if reference.shape != shape:
        raise ValueError(f"reference must have shape {shape}, got {reference.shape}")
    return _Force(_Forces(phase), reference, _root(weight))


class _Barrier(eqx.Module):
    residual: eqx.Module
    lower: Array
    upper: Array
    root: Array

    def __call__(self, q: Array, v: Array, u: Array | None = None) -> Array:
        r = self.residual(q, v, u)
        return self.root * (jnp.minimum(r - self.lower, 0.0) + jnp.maximum(r - self.upper, 0.0))


def barrier_residual(residual, lower=-jnp.inf, upper=jnp.inf, weight=1.0) -> eqx.Module:
    """A residual outside bounds: r = sqrt(w) (min(r0 - lower, 0) + max(r0 - upper, 0)), zero
    within them (Crocoddyl's `ActivationModelQuadraticBarrier`), e.g. joint limits on a
    `state_residual`.

    Args:
        residual: the residual function r0(q, v, u=None).
        lower (float | Array): the lower bounds, a scalar or one per component; -inf for none.
        upper (float | Array): the upper bounds, likewise.
        weight (float | Array): w.

    Returns:
        The residual function r(q, v, u=None), r0's shape.
    """
    return _Barrier(residual, jnp.asarray(lower, dtype=float), jnp.asarray(upper, dtype=float),
                    _root(weight))


class _WrenchCone(eqx.Module):
    forces: _Forces
    A: Array                       # rows on the ground-frame wrench (torque; force), per contact
    rotations: Array               # each ground frame (t1, t2, n) in world components
    root: Array

    def __call__(self, q: Array, v: Array, u: Array) -> Array:
        w = self.forces(q, v, u)
        local = jnp.concatenate([jnp.einsum("kji,kj->ki", self.rotations, w[:, :3]),
                                 jnp.einsum("kji,kj->ki", self.rotations, w[:, 3:])], axis=1)
        r = jnp.einsum("kij,kj->ki", self.A, local)
        # the normal force's row (the fifth) bounded below by 0, every other row above by 0
        return self.root * jnp.concatenate([jnp.maximum(r[:, :4], 0.0),
                                            jnp.minimum(r[:, 4:5], 0.0),
                                            jnp.maximum(r[:, 5:], 0.0)], axis=1).ravel()


def wrench_cone_residual(phase, mu=0.7, length=0.1, width=0.05, weight=1.0,
                         inner: bool = True) -> eqx.Module:
    """Each surface contact's wrench outside the contact wrench cone of its rectangular sole,
    with a bounded activation (Crocoddyl's `ResidualModelContactWrenchCone` with
    `ActivationModelQuadraticBarrier`, its biped examples' cost): no slipping (a linearised
    friction cone), no pulling, the centre of pressure within the sole and a yaw torque that
    friction can carry (Caron, Pham and Nakamura 2015).

    Args:
        phase: the stance, as `mbjax.contact.stance` made it from surface contacts; each
            sole's rectangle is centred at its frame, its length along the ground's first
            tangent and its width along the second
            (`ground_frame`: the world's x and y on a ground of normal z, as Crocoddyl's
            `WrenchCone` with its surface rotation), the wrench taken in those axes.
        mu: the friction coefficient, positive.
        length: the sole's length [m].
        width: the sole's width [m].
        weight (float | Array): w.
        inner: the friction pyramid inscribed in the cone (mu / sqrt(2) on each side), as
            Crocoddyl's default; else circumscribed.

    Returns:
        The residual function r(q, v, u), shape (17 len(contacts),).

    Raises:
        ValueError: mu, length or width is not positive, or the phase is not a stance.
    """
    for name, x in (("mu", mu), ("length", length), ("width", width)):
        if not (np.ndim(x) == 0 and float(x) > 0 and np.isfinite(float(x))):
            raise ValueError(f"{name} must be positive, got {x!r}")
    contacts = stance_contacts(phase)
    A = jnp.asarray(np.stack([wrench_cone_rows(float(mu), float(length), float(width), inner)]
                             * len(contacts)))
    rotations = jnp.stack([ground_frame(c.normal) for c in contacts])
    return _WrenchCone(_Forces(phase), A, rotations, _root(weight))
