"""Residuals for the common costs of Crocoddyl's examples, as cost functions for a `Problem`.

Each helper returns an equinox module r(q, v, u) (u optional, so one serves as a running and a
terminal cost) giving a vector of residuals, which `Problem` reads as the cost 1/2 |r|^2 and
expands by Gauss-Newton. A weight w (a scalar, or one per residual component) scales the residual
by sqrt(w), so that the cost is w 1/2 |r|^2: Crocoddyl's `CostModelResidual` with its weight and a
quadratic (`ActivationModelQuad`) or weighted quadratic (`ActivationModelWeightedQuad`)
activation. Being modules, their targets and weights are leaves: a problem with another target
reuses the compiled solve. A tuple of them is their sum (`Problem`'s running and terminal).
"""

import equinox as eqx
import jax.numpy as jnp
from jax import Array

from mbjax._src.lie import gamma_inv, log
from mbjax._src.rigid.frames import frame_pose


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
        TypeError: space has no `difference`.
    """
    if not hasattr(space, "difference"):
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
