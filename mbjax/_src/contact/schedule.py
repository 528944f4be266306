"""A contact schedule simulated: each phase a stance, an impulse where feet land."""

from collections.abc import Sequence

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jax import Array

from mbjax._src.contact.impulse import impulse
from mbjax._src.contact.stance import _contacts, contact_wrenches, stance
from mbjax._src.integrate.base import AbstractIntegrator
from mbjax._src.integrate.simulate import simulate
from mbjax._src.system.accuracy import number
from mbjax._src.system.status import Flags, flags, Status, WithStatus
from mbjax._src.system.tree_system import AbstractTreeSystem


class ContactSolution(WithStatus):
    """A simulated contact schedule (`simulate_schedule`): its states, the ground's wrench on
    each foot and the status of the whole run.

    Args:
        ts: the saved times [s], every step of every phase, shape (T,).
        qs: configurations, shape (T, nq).
        vs: velocities, shape (T, nv).
        wrenches: the ground's wrench on each of `frames` at each saved time, (torque; force) in
            world components at the frame [N m; N], zeros where the frame is off the ground,
            shape (T, len(frames), 6).
        phases: the phase of each saved time, shape (T,).
        status: the runs' `Status` flags OR-ed over the phases (PULLING or SLIPPING where a
            foot held on the ground pulled or slipped).
        frames: the schedule's contact frames, in order of first appearance.
        phase_status: each phase's own status, shape (number of phases,).
    """

    ts: Array
    qs: Array
    vs: Array
    wrenches: Array
    phases: Array
    status: Flags = eqx.field(converter=flags)
    phase_status: Flags = eqx.field(converter=flags)
    frames: tuple = eqx.field(static=True)

    def notes(self, i: int) -> dict:
        """Where each flag was raised: the phases, by index, and their status."""
        codes = np.asarray(self.phase_status)
        out = {}
        for k, code in enumerate(codes):
            for flag in Status:
                if flag and int(code) & flag:
                    out.setdefault(flag, []).append(f"phase {k}")
        return {flag: "in " + ", ".join(where) for flag, where in out.items()}


def simulate_schedule(tree: AbstractTreeSystem, integrator: AbstractIntegrator, q0: Array,
                      v0: Array, schedule: Sequence, *, dt: float, mu=None) -> ContactSolution:
    """Simulate a robot through a contact schedule: phase after phase, its feet held on the
    ground (`stance`), an impulse where feet land (`impulse`), the ground's wrenches saved.

    Each phase starts where the last one ended; the contacts it adds land with a perfectly
    inelastic impulse on all of its contacts (those already down stay at rest), and it runs
    `mbjax.simulate` on its stance (Crocoddyl's Baumgarte gains), every step saved. With a
    friction coefficient each phase's stance watches its feet, so a foot that pulls on the
    ground or slips makes the run fail with `Status.PULLING` or `Status.SLIPPING`: the
    controller asked for what the contacts cannot give.

    Args:
        tree: the robot with its controller, a rigid tree system (`TreeSystem(model, control)`).
        integrator: the fixed-step method (`RK4()`, ...).
        q0: initial configuration, shape (nq,).
        v0: initial velocity, shape (nv,).
        schedule: the phases in order, each a pair (contacts, duration [s]): the
            `PointContact`s and `SurfaceContact`s held, for a whole number of steps (those
            made with active=False are in the air); an empty contact list for a flight.
        dt: the step [s].
        mu (float | None): the friction coefficient of the watch (`stance`); None for none.

    Returns:
        A `ContactSolution`; where a phase blows up (NONFINITE), the phases after it are not
            run.

    Raises:
        ValueError: an empty schedule, a duration that is not a positive whole number of steps,
            or dt not a positive number.
        TypeError: a phase that is not (contacts, duration).
        KeyError: a contact's frame is not in the model.
    """
    dt = number(dt, "dt")
    if not dt > 0:
        raise ValueError(f"dt must be a positive step [s], got {dt}")
    phases = list(schedule)
    if not phases:
        raise ValueError("schedule must hold at least one phase (contacts, duration)")
    frames, checked = [], []
    for i, phase in enumerate(phases):
        if not (isinstance(phase, tuple | list) and len(phase) == 2):
            raise TypeError(f"schedule[{i}] must be a pair (contacts, duration), got {phase!r}")
        contacts, duration = phase
        contacts = _contacts(contacts) if len(contacts) else ()
        contacts = tuple(c for c in contacts if bool(c.active))      # those in the air: none
        steps = float(duration) / dt
        if not (steps >= 1 and abs(steps - round(steps)) < 1e-9 * max(1.0, steps)):
            raise ValueError(f"schedule[{i}]: the duration must be a positive whole number of "
                             f"steps dt = {dt}, got {duration!r}")
        frames += [c.frame for c in contacts if c.frame not in frames]
        checked.append((contacts, round(steps) * dt))
    q, v, t, held = jnp.asarray(q0, float), jnp.asarray(v0, float), 0.0, ()
    parts = []
    for k, (contacts, duration) in enumerate(checked):
        landing = [c for c in contacts if c.frame not in {h.frame for h in held}]
        if landing:
            v = impulse(tree.model, q, v, contacts)[0]
        if contacts:
            system = stance(tree, q, contacts, mu=mu)
        else:
            system = tree
        sol = simulate(system, integrator, q, v, dt=dt, t0=t, t1=t + duration)
        w = jnp.zeros((sol.ts.shape[0], len(frames), 6))
        if contacts:
            forces = jax.vmap(lambda t_, q_, u_, s=system: contact_wrenches(s, t_, q_, u_))(
                sol.ts, sol.qs, sol.vs)
            w = w.at[:, [frames.index(c.frame) for c in contacts]].set(forces)
        keep = slice(0, None) if k == 0 else slice(1, None)     # a phase's first state is the
        parts.append((sol.ts[keep], sol.qs[keep], sol.vs[keep], w[keep],     # last one's end
                      jnp.full(sol.ts[keep].shape, k), sol.status))
        q, v, t, held = sol.qs[-1], sol.vs[-1], t + duration, contacts
        if not isinstance(q, jax.core.Tracer) and not bool(jnp.all(jnp.isfinite(q))):
            break                       # blown up (NONFINITE): no pose to start the next from
    ts, qs, vs, ws, ks, codes = zip(*parts, strict=True)
    phase_status = jnp.stack(codes)
    status = jax.lax.reduce(phase_status, np.int32(0), jax.lax.bitwise_or, (0,))
    return ContactSolution(jnp.concatenate(ts), jnp.concatenate(qs), jnp.concatenate(vs),
                           jnp.concatenate(ws), jnp.concatenate(ks), status, phase_status,
                           tuple(frames))

