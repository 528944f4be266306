"""Plausibility of a body's mass and inertia: what is an error, what only a warning.

Errors are kept for data that makes the computation meaningless: non-finite numbers, a negative
mass (a sign error, never round-off), an asymmetric inertia. Data that is implausible but
computable loads, as Pinocchio loads it, with a `ModelWarning` that names the body and the fix:
CAD inertias that break the triangle inequality J1 + J2 >= J3, negative principal moments
(round-off, or wrong data that may make the mass matrix indefinite), a massless body at the end
of a moving joint (its mass matrix is singular). `strict=True` turns those warnings into errors.
"""

import warnings

import numpy as np

# A principal moment below zero by at most this fraction of the largest one (or by 1e-7 kg m^2)
# is round-off in the source data, not a wrong sign.
ROUND_OFF = 1e-4
ROUND_OFF_ABS = 1e-7

MASSLESS_REMEDY = ("give its joint armature (Model(..., armature=...)) or bound the mass and "
                   "inertia from below (load_urdf(..., min_mass=..., min_inertia=...), like "
                   "MuJoCo's compiler options boundmass and boundinertia)")


class ModelWarning(UserWarning):
    """The warning for model data that is implausible but computable.

    Raised as a warning when a model loads with inertias that break the triangle inequality,
    negative principal moments, a body with inertia but no mass, or a massless body at the end
    of a moving joint; the message names the body and the fix. `strict=True` (of `Model`,
    `load_urdf`, ...) makes it a `ValueError`; `warnings.simplefilter("error", ModelWarning)`
    turns it into an exception process-wide.
    """


def warn(message: str, strict: bool) -> None:
    if strict:
        raise ValueError(message + " (strict=True)")
    warnings.warn(message, ModelWarning, stacklevel=4)


def check_body(mass: float, inertia: np.ndarray, name: str, *, carries: bool,
               strict: bool = False) -> None:
    """Validate one body's mass and inertia about its centre of mass (see the module).

    Args:
        mass: the body's mass [kg].
        inertia: its inertia about the centre of mass, shape (3, 3) [kg m^2].
        name: how messages name the body.
        carries: the body carries others, or its joint has armature (so a massless body is
            fine).
        strict: raise where the data is only implausible.

    Raises:
        ValueError: non-finite data, a negative mass, an asymmetric inertia; with strict=True
            also implausible data.
    """
    J = np.asarray(inertia, dtype=float)
    if not (np.isfinite(mass) and np.all(np.isfinite(J))):
        raise ValueError(f"{name}: mass and inertia must be finite, got mass {mass} and inertia "
                         f"{J.tolist()}")
    if mass < 0:
        raise ValueError(f"{name}: mass must be positive, got {mass}")
    if not np.allclose(J, J.T, rtol=1e-9, atol=1e-12 * max(np.abs(J).max(), 1.0)):
        raise ValueError(f"{name}: inertia must be symmetric, got\n{J}")
    moments = np.linalg.eigvalsh(J)
    tol = max(ROUND_OFF * abs(moments[-1]), ROUND_OFF_ABS)
    if mass == 0 and not J.any():
        if not carries:
            warn(f"{name} is massless and carries no other body: its joint has no inertia to act "
                 f"on (no armature either) and the mass matrix is singular; {MASSLESS_REMEDY}",
                 strict)
        return
    if mass == 0:
        warn(f"{name} has rotational inertia but no mass; give it the mass of its parts", strict)
    elif moments[0] < -tol:
        warn(f"{name}: inertia is not positive semi-definite (principal moments {moments}): the "
             "mass matrix may be indefinite; the dynamics use it as given, fix the source data",
             strict)
        return
    elif moments[0] < 0:
        warn(f"{name}: principal moments {moments} are negative by round-off; the dynamics use "
             "them as given (fix the source data, or clip them at zero)", strict)
    if moments[0] + moments[1] < moments[2] * (1 - 1e-9) - tol:
        warn(f"{name}: principal moments {moments} violate the triangle inequality J1 + J2 >= J3 "
             "that every mass distribution satisfies (typical of CAD exports); the dynamics use "
             "them as given, fix the inertia to make it physical", strict)


def combine(parts) -> tuple[float, np.ndarray, np.ndarray]:
    """(mass, centre of mass, inertia about it) of rigidly joined parts, each (mass, centre of
    mass, inertia about it) in one frame (parallel axes); massless parts (a pure rotational
    inertia) add their inertia as it is."""
    mass = sum(p[0] for p in parts)
    if mass == 0:
        return 0.0, np.zeros(3), sum((p[2] for p in parts), np.zeros((3, 3)))
    com = sum(p[0] * p[1] for p in parts) / mass
    inertia = np.zeros((3, 3))
    for m_i, c_i, J_i in parts:
        d = c_i - com
        inertia += J_i + m_i * (d @ d * np.eye(3) - np.outer(d, d))
    return float(mass), com, inertia
