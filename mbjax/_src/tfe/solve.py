"""Time marching element by element: `solve_tfe` (Borri 1990 §5).

Each element starts from the converged end state of the previous one. Its reference (§2), a
strategy (`AbstractReference`), is built from that state and the incremental coordinates start at
zero (`ConstantReference`, `ConstantVelocityReference`); or one prescribed reference motion
(`Reference`) is followed throughout and the increments carry over (§6-7). Newton solves the
element's equations (eqs 5.3 / 5.8) and the end state (R_2, x_2, p_hat_2) is carried on. Elements
are a `lax.scan`, Newton a `lax.while_loop` differentiated by the implicit function theorem, so
`jax.grad` of any function of the solution with respect to the initial state or the body's
parameters is exact and cheap.
"""

import dataclasses
from functools import partial

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jax import Array

from mbjax._src.lie.inputs import check_point, check_rotation
from mbjax._src.system.accuracy import DRIFT_LIMIT, doubled, sample_indices, tolerances
from mbjax._src.system.invariants import drifts
from mbjax._src.system.status import (Flags, flags, DRIFTED, ESTIMATED, FLAGS, Status, WithStatus,
                                      accuracy_notes, raise_on_failure)
from mbjax._src.tfe.body import Body
from mbjax._src.tfe.elements import Element
from mbjax._src.tfe.form import AbstractForm
from mbjax._src.tfe.mixed import Mixed
from mbjax._src.tfe.newton import NewtonInfo, newton
from mbjax._src.tfe.reference import (AbstractReference, ConstantVelocityReference, Reference,
                                      check_reference, configuration)


class State(eqx.Module):
    """The body's state at an element boundary (build one with `initial_state`).

    Args:
        R: rotation body to space, shape (3, 3).
        x: position of O' in space, shape (3,) [m].
        p_hat: spatial momentum (h, l) about O' (h only, about a fixed point), shape (nq,).
    """

    R: Array
    x: Array
    p_hat: Array


def initial_state(body: Body, R0, Omega0, x0=(0.0, 0.0, 0.0), v0=(0.0, 0.0, 0.0)) -> State:
    """The initial state of `solve_tfe` from an attitude and velocities.

    The momentum is p_hat = M6 w (eq 3.19) with w = (R0 Omega0, v0).

    Args:
        body: the body.
        R0 (Array): rotation body to space, shape (3, 3).
        Omega0 (Array): angular velocity in the body frame, shape (3,) [rad/s].
        x0 (Array): position of O', shape (3,) [m].
        v0 (Array): velocity of O' in space, shape (3,) [m/s] (ignored about a fixed point).

    Returns:
        The `State` (R0, x0, p_hat).
    """
    R0 = check_rotation(R0, "R0")
    Omega0, x0, v0 = (check_point(x, name) for x, name in ((Omega0, "Omega0"), (x0, "x0"),
                                                            (v0, "v0")))
    w = R0 @ Omega0
    if not body.fixed_point:
        w = jnp.concatenate([w, v0])
    return State(R0, x0, body.mass_matrix(R0) @ w)


class TFESolution(WithStatus):
    """The result of `solve_tfe`: states at the element boundaries and per-element Newton records.

    The status has NOT_CONVERGED where an element's Newton missed its tolerance, NONFINITE
    where the state blew up, INACCURATE past the tolerance asked for.

    Args:
        ts: boundary times [s], shape (n_elements + 1,).
        R: rotations at the boundaries, shape (n_elements + 1, 3, 3).
        x: positions of O', shape (n_elements + 1, 3) [m].
        p_hat: spatial momenta about O', shape (n_elements + 1, nq).
        iterations: Newton iterations per element, shape (n_elements,).
        residual: each element's final residual norm, shape (n_elements,).
        status: the `Status` flags, as `Flags` (an integer array that prints in words).
        error: the estimated error of the final state, as `mbjax.integrate.Solution`'s (NaN
            where no tolerance was asked).
        drift: the invariants' largest relative drift over the boundaries, as
            `mbjax.integrate.Solution`'s.
        drifting: the index of the invariant that drifted most.
        flagged_at: the time [s] each `Status` flag was first raised (NaN: never), shape (8,).
        inaccurate_by: why the march is INACCURATE (a mask, as `mbjax.integrate.Solution`'s).
        invariant_names: the names of the body's invariants (static).
    """

    ts: Array
    R: Array
    x: Array
    p_hat: Array
    iterations: Array
    residual: Array
    status: Flags = eqx.field(converter=flags)
    error: Array = float("nan")
    drift: Array = float("nan")
    drifting: Array = -1
    flagged_at: Array | None = None
    inaccurate_by: Array = 0
    invariant_names: tuple[str, ...] = eqx.field(static=True, default=())

    def notes(self, i: int) -> dict:
        """What tripped each flag of the i-th march (`WithStatus.messages`)."""
        return accuracy_notes(self, i, self.flagged_at)

    def energy(self, body: Body) -> Array:
        """The total energy at every boundary.

        Args:
            body: the body the solution was computed for.

        Returns:
            The energy [J], shape (n_elements + 1,).
        """
        return jax.vmap(body.energy)(self.R, self.x, self.p_hat)

    def angular_momentum(self, body: Body) -> Array:
        """The spatial angular momentum about the origin, h + x x l (eq 3.2), at every boundary.

        Args:
            body: the body the solution was computed for.

        Returns:
            The angular momentum, shape (n_elements + 1, 3) [kg m^2/s].
        """
        h = self.p_hat[:, :3]
        return h if body.fixed_point else h + jnp.cross(self.x, self.p_hat[:, 3:])


def element_map(form: AbstractForm, body: Body, ref: Reference, element: Element, dt, z1: Array,
                *, tol=1e-10, max_iter: int = 20) -> tuple[Array, NewtonInfo]:
    """The end state z_2 = (p_2, q_2) of one element from its start z_1 = (p_1, q_1).

    Both are in the form's variables about the reference `ref`. Its Jacobian dz_2/dz_1
    (jax.jacfwd, through the implicit function theorem) is the element's transition matrix
    (eq 6.7).

    Args:
        form: the weak form.
        body: the body.
        ref: the element's reference motion.
        element: the time element.
        dt: the node spacing [s].
        z1: the start state, shape (2 nq,).
        tol: Newton's tolerance on the step, relative to 1 + |U|.
        max_iter: the most Newton iterations.

    Returns:
        z2: the end state, shape (2 nq,).
        info: the Newton solve's record (`NewtonInfo`).
    """
    U, info = newton(lambda U: form.residual(body, ref, element, dt, U, z1),
                     form.guess(body, ref, element, z1), tol=tol, max_iter=max_iter)
    return form.final(body, ref, element, dt, U, z1), info


def _advance(body, state: State, t, dt, tol, reference: AbstractReference, *, form, element,
             max_iter) -> tuple[State, NewtonInfo]:
    """One element of node spacing dt from `state` at time t (its reference built from the
    state, or the prescribed one shifted to t: `AbstractReference.start`)."""
    nq = body.nq
    ref, q1 = reference.start(body, t, state.R, state.x, state.p_hat)
    z1 = jnp.concatenate([form.to_form(body, q1, state.p_hat), q1])
    z2, info = element_map(form, body, ref, element, dt, z1, tol=tol, max_iter=max_iter)
    q2 = z2[nq:]
    R2, x2 = configuration(body, ref, q2, element.length(dt))
    return State(R2, x2, form.from_form(body, q2, z2[:nq])), info


_STATIC = ("form", "element", "reference", "max_iter")


@partial(jax.jit, static_argnames=(*_STATIC, "n_elements"))
def _march(body, state0, dt, tol, dynamic, *, form, element, n_elements, reference, max_iter):
    """The march; the reference strategy split into its arrays (`dynamic`, traced: a prescribed
    motion's) and the rest (`reference`, static)."""
    h = element.length(dt)
    reference = eqx.combine(dynamic, reference)

    def step(state, k):
        new, info = _advance(body, state, k * h, dt, tol, reference, form=form, element=element,
                             max_iter=max_iter)
        return new, (new, info.iterations, info.residual, info.converged)

    _, (states, iterations, residual, converged) = jax.lax.scan(step, state0, jnp.arange(n_elements))
    join = lambda a, b: jnp.concatenate([a[None], b])  # noqa: E731
    R, x, p_hat = (join(getattr(state0, k), getattr(states, k)) for k in ("R", "x", "p_hat"))
    finite = (jnp.all(jnp.isfinite(p_hat), axis=1) & jnp.all(jnp.isfinite(R), axis=(1, 2))
              & jnp.all(jnp.isfinite(x), axis=1))
    status = (jnp.where(jnp.all(converged), 0, int(Status.NOT_CONVERGED))
              | jnp.where(jnp.all(finite), 0, int(Status.NONFINITE)))
    ts = jnp.arange(n_elements + 1) * h
    first = jnp.full(len(FLAGS), jnp.nan, ts.dtype)
    first = first.at[FLAGS.index(Status.NONFINITE)].set(_first(ts, ~finite))
    first = first.at[FLAGS.index(Status.NOT_CONVERGED)].set(_first(ts[1:], ~converged))
    return TFESolution(ts, R, x, p_hat, iterations, residual, status, flagged_at=first)


def _first(ts, where):
    """The first of `ts` where `where` holds, NaN if none."""
    return jnp.where(jnp.any(where), ts[jnp.argmax(where)], jnp.nan)


@jax.jit
def _checked(body, solution: TFESolution, drift_limit) -> TFESolution:
    """The solution with the default check (`solve_tfe`): the invariants' drift past
    `drift_limit`."""
    history = jax.vmap(body.invariants)(solution.ts, solution.R, solution.x, solution.p_hat)
    ratios = drifts(history)
    drift = jnp.max(ratios, initial=0.0)
    over = jnp.max(ratios, axis=1) > drift_limit
    drifted = jnp.any(over)
    k = FLAGS.index(Status.INACCURATE)
    first = solution.flagged_at.at[k].set(jnp.where(drifted, solution.ts[jnp.argmax(over)],
                                                    jnp.nan))
    status = solution.status | jnp.where(drifted, int(Status.INACCURATE), 0)
    by = jnp.where(drifted, DRIFTED, 0)
    return dataclasses.replace(solution, status=status.astype(solution.status.dtype),
                               drift=drift,
                               drifting=jnp.argmax(jnp.max(ratios, axis=0)), flagged_at=first,
                               inaccurate_by=by, invariant_names=history.labels())


@partial(jax.jit, static_argnames=(*_STATIC, "n_elements"))
def _error_estimate(body, states: State, ts, dt, tol, dynamic, rtol, atol, *, form, element,
                    n_elements, reference, max_iter):
    """(estimated global error, its ratio to the tolerance) by step doubling from the sampled
    boundary states (see `solve_tfe`; the reference split as `_march`'s)."""
    advance = partial(_advance, body, tol=tol, reference=eqx.combine(dynamic, reference),
                      form=form, element=element, max_iter=max_iter)
    h = element.length(dt)

    def flat(s):
        return jnp.concatenate([s.R.ravel(), s.x, s.p_hat])

    def local(state, t):
        full, _, half = doubled(lambda s, t, dt: advance(s, t, dt)[0], state, t, dt, h)
        full, half = flat(full), flat(half)
        e = full - half
        scale = atol + rtol * jnp.maximum(jnp.abs(flat(state)), jnp.abs(full))
        return jnp.max(jnp.abs(e)), jnp.sqrt(jnp.mean((e / scale) ** 2))

    errors, ratios = jax.vmap(local)(states, ts)
    return n_elements * jnp.mean(errors), n_elements * jnp.mean(ratios)


def _checked_state(body: Body, state0) -> State:
    """state0 with its shapes checked against the body ((3, 3), (3,), (nq,)) and its R a
    rotation where concrete; errors name the field."""
    if not isinstance(state0, State):
        raise TypeError(f"state0 must be a tfe.State (initial_state(body, R0, Omega0)), got "
                        f"{type(state0).__name__}")
    x, p_hat = (jnp.asarray(a, dtype=float) for a in (state0.x, state0.p_hat))
    for name, value, shape in (("x", x, (3,)), ("p_hat", p_hat, (body.nq,))):
        if value.shape != shape:
            raise ValueError(f"state0.{name} must have shape {shape} for this body, got "
                             f"{value.shape}")
    return State(check_rotation(state0.R, "state0.R"), x, p_hat)


def solve_tfe(body: Body, state0: State, *, dt, n_elements: int, form: AbstractForm = Mixed(),
              element: Element = Element(4),
              reference: AbstractReference = ConstantVelocityReference(),
              tol=1e-10, max_iter: int = 20, rtol: float | None = None,
              atol: float | None = None, throw: bool = False) -> TFESolution:
    """March a body through `n_elements` time elements of a weak form (Borri 1990 §5).

    Each element spans (nodes - 1) dt; Newton solves its equations, differentiated by the
    implicit function theorem. The solution holds the states at the elements' boundaries and a
    status that flags an unconverged element, a non-finite state or an inaccurate run.

    Args:
        body: the body.
        state0: the initial state (`initial_state`).
        dt (float): the node spacing [s].
        n_elements: the number of elements, a positive int.
        form: the weak form, a strategy (`Mixed()`, `PrimalUnsymmetric()`, ...).
        element: the time element (nodes and quadrature).
        reference: what each element is written about, a strategy: `ConstantReference()` or
            `ConstantVelocityReference()` (the default), built afresh for each element from its
            initial state, or a `Reference` motion (from t = 0) followed by the whole march: the
            increments then carry over between elements, as in the linearized analysis of
            §6-7, and must stay below pi in rotation.
        tol (float): Newton's tolerance on the step, relative to 1 + |U|.
        max_iter: the most Newton iterations per element.
        rtol: relative tolerance on the final state's error and the invariants' drift.
        atol: absolute tolerance on the final state's error.
        throw: raise an error naming the failure (an element's Newton iteration not
            converged, a non-finite state, an inaccurate run) instead of returning the solution
            with its status.

    Returns:
        The `TFESolution` at the n_elements + 1 boundaries.

    Raises:
        ValueError: n_elements or max_iter is not a positive int, tol is not positive and
            finite, rtol and atol are negative or both zero, or state0's arrays have the wrong
            shapes or its R is not a rotation.
        TypeError: element is not an `Element`, form not a form instance, reference not a
            reference strategy (the strings "constant" and "constant_velocity" of old, say), or
            state0 not a `State`.
        equinox.EquinoxRuntimeError: with throw=True, the march failed.

    More on compilation, default accuracy check, accuracy with a tolerance: the documentation
    site's Details page (docs/details.md).
    """
    check_reference(reference)
    for name, value in (("n_elements", n_elements), ("max_iter", max_iter)):
        if not (isinstance(value, int) and not isinstance(value, bool) and value >= 1):
            raise ValueError(f"{name} must be a positive int, got {value!r}")
    if not isinstance(element, Element):
        raise TypeError(f"element must be a tfe.Element, got {type(element).__name__}")
    if not isinstance(form, AbstractForm):
        hint = " (an instance: Mixed(), not Mixed)" if isinstance(form, type) else ""
        raise TypeError(f"form must be a weak form such as Mixed(){hint}, got {form!r}")
    if not isinstance(tol, jax.core.Tracer) and not (float(tol) > 0 and np.isfinite(tol)):
        raise ValueError(f"tol must be positive and finite (Newton's tolerance), got {tol!r}")
    state0 = _checked_state(body, state0)
    dt = jnp.asarray(dt, dtype=float)
    checked = rtol is not None or atol is not None
    if checked:
        rtol, atol = tolerances(rtol, atol)
    tol = jnp.asarray(tol, dtype=float)
    dynamic, reference = eqx.partition(reference, eqx.is_array_like)
    static = dict(form=form, element=element, n_elements=n_elements, reference=reference,
                  max_iter=max_iter)
    solution = _march(body, state0, dt, tol, dynamic, **static)
    solution = _checked(body, solution, rtol if checked and rtol > 0 else DRIFT_LIMIT)
    if checked:
        picks = jnp.asarray(sample_indices(n_elements))
        states = State(solution.R[picks], solution.x[picks], solution.p_hat[picks])
        error, ratio = _error_estimate(body, states, solution.ts[picks], dt, tol, dynamic,
                                       rtol, atol, **static)
        estimated = ratio > 1.0
        k = FLAGS.index(Status.INACCURATE)
        first = solution.flagged_at.at[k].set(jnp.where(
            jnp.isnan(solution.flagged_at[k]) & estimated, solution.ts[-1],
            solution.flagged_at[k]))
        status = solution.status | jnp.where(estimated, int(Status.INACCURATE), 0)
        solution = eqx.tree_at(lambda s: (s.status, s.error, s.flagged_at, s.inaccurate_by),
                               solution, (status.astype(solution.status.dtype), error, first,
                                          solution.inaccurate_by
                                          | jnp.where(estimated, ESTIMATED, 0)))
    return raise_on_failure(solution, throw, "mbjax.tfe.solve_tfe")
