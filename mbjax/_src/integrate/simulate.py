"""The fixed-step simulation driver."""

import math
from typing import NamedTuple

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jax import Array

from mbjax._src.integrate.base import AbstractIntegrator
from mbjax._src.integrate.solution import Solution
from mbjax._src.lie.inputs import check_unit_quaternions
from mbjax._src.system.accuracy import (DEFAULT_DRIFT_LIMIT, ERROR_SAMPLES, RESOLUTION_LIMIT,
                                        SUSTAINED, doubled, number, sample_indices, step_ratio,
                                        tolerances)
from mbjax._src.system.invariants import drifts
from mbjax._src.system.status import (DRIFTED, ESTIMATED, FLAGS, RESOLVED, Status,
                                      raise_on_failure)
from mbjax._src.system.system import AbstractSystem


def _state(x, name: str, size: int | None) -> Array:
    """q0 or v0 as a real array in the working precision (integers and float32 promoted, as
    a carry of the time loop must keep its type), its length checked where the system has
    one."""
    try:
        x = jnp.asarray(x)
    except TypeError as error:
        raise TypeError(f"{name} must be an array of real numbers, got {type(x).__name__}") \
            from error
    if jnp.iscomplexobj(x) or not (jnp.issubdtype(x.dtype, jnp.number) or x.dtype == bool):
        raise TypeError(f"{name} must be real, got dtype {x.dtype}")
    working = jnp.result_type(float)
    if x.dtype != working and not (jnp.issubdtype(x.dtype, jnp.floating)
                                   and jnp.finfo(x.dtype).bits > jnp.finfo(working).bits):
        x = x.astype(working)
    if size is not None and x.shape != (size,):
        raise ValueError(f"{name} must have shape ({size},) for this system, got {x.shape}")
    return x


def _save_indices(t0: float, t1: float, dt: float, saveat) -> tuple[int, np.ndarray]:
    """Number of steps and the step indices of the save times (validated on the step grid)."""
    if not dt > 0:
        raise ValueError(f"dt must be positive, got {dt}")
    span = t1 - t0
    n_steps = round(span / dt)
    if n_steps < 1 or abs(n_steps * dt - span) > 1e-9 * max(1.0, abs(span)):
        raise ValueError(f"t1 - t0 = {span} must be a positive whole number of steps dt = {dt}")
    if saveat is None:
        return n_steps, np.arange(n_steps + 1)
    try:
        ts = np.atleast_1d(np.asarray(saveat, dtype=float))
    except (TypeError, ValueError) as error:
        raise TypeError(f"saveat must be None or times (real numbers), got {saveat!r:.60}") \
            from error
    if ts.ndim != 1 or not ts.size:
        raise ValueError(f"saveat must be None or a non-empty 1-D array of times, got shape "
                         f"{ts.shape}")
    if not np.all(np.isfinite(ts)):
        raise ValueError(f"saveat times must be finite, got {ts}")
    idx = np.round((ts - t0) / dt).astype(int)
    off_grid = np.abs(t0 + idx * dt - ts) > 1e-9 * max(1.0, abs(span))
    if np.any(off_grid) or np.any(idx < 0) or np.any(idx > n_steps):
        raise ValueError(f"saveat times must lie on the step grid t0 + k dt within [t0, t1]; "
                         f"offending times: {ts[off_grid | (idx < 0) | (idx > n_steps)]}")
    if np.any(np.diff(idx) < 0):
        raise ValueError("saveat times must be increasing")
    return n_steps, idx


def simulate(system: AbstractSystem, integrator: AbstractIntegrator, q0: Array, v0: Array, *,
             dt: float, t1: float, t0: float = 0.0, saveat=None, checkpoint: bool = False,
             rtol: float | None = None, atol: float | None = None,
             throw: bool = False) -> Solution:
    """Integrate `system` from (q0, v0) at t0 to t1 with fixed steps dt.

    A `Solution` whose status flags a failed or inaccurate run. dt, t0, t1 and saveat are
    concrete numbers; everything else may be traced (`jax.grad`, `jax.vmap`, `jax.jit`).

    Args:
        system: the system to integrate (`TreeSystem(model)`, `RigidBody`, `ClosedSystem`,
            ...), an `AbstractSystem` instance.
        integrator: the fixed-step method, an `AbstractIntegrator` instance (`RK4()`, ...).
        q0: initial configuration, shape (nq,).
        v0: initial velocity coordinates, shape (nv,).
        dt: the step [s], a positive concrete number; t1 - t0 must be a whole number of steps.
        t1: the final time [s].
        t0: the initial time [s].
        saveat (Array | None): None (every step) or the save times [s], a 1-D increasing array
            on the grid t0 + k dt within [t0, t1].
        checkpoint: for reverse-mode gradients of long rollouts: `jax.grad` keeps the states
            at segments of about sqrt(T) steps and recomputes one at a time (`jax.checkpoint`),
            memory like sqrt(T) rather than T for about one more forward pass; same values.
        rtol: relative tolerance on the final state's error and on the invariants' drift
            (held to 1 % without a tolerance: docs/details.md); None for 0 where atol is given.
        atol: absolute tolerance on the final state's error, in the state's units.
        throw: raise an error naming the failure (`Status.failures()`) instead of returning a
            solution whose status carries it (also under `jit` and `vmap`, through
            `eqx.error_if`).

    Returns:
        A `Solution` with the saved times ts (T,), states qs (T, nq) and vs (T, nv), the
            status, the invariants' drift, and with a tolerance the error estimate.

    Raises:
        TypeError: naming the argument: system or integrator not an mbjax instance, q0 or v0
            not real, dt, t0, t1, rtol or atol traced or not a real number.
        ValueError: naming the argument: a non-positive dt or one that does not divide t1 - t0,
            saveat off the grid, q0 or v0 of the wrong shape, a quaternion in q0 not of unit
            norm, rtol and atol negative or both zero.
        equinox.EquinoxRuntimeError: with throw=True, the run failed.

    More on the rollout, default accuracy check, accuracy with a tolerance: the documentation
    site's Details page (docs/details.md).
    """
    if not isinstance(system, AbstractSystem):
        hint = (" (wrap a Model in TreeSystem(model))" if type(system).__name__ == "Model"
                else " (an instance, not the class)" if isinstance(system, type) else "")
        raise TypeError(f"system must be an mbjax system such as TreeSystem(model){hint}, got "
                        f"{system.__name__ if isinstance(system, type) else type(system).__name__}")
    if not isinstance(integrator, AbstractIntegrator):
        hint = " (an instance: RK4(), not RK4)" if isinstance(integrator, type) else ""
        raise TypeError(f"integrator must be an mbjax integrator such as RK4(){hint}, got "
                        f"{integrator.__name__ if isinstance(integrator, type) else type(integrator).__name__}")
    dt, t0, t1 = (number(x, name) for x, name in ((dt, "dt"), (t0, "t0"), (t1, "t1")))
    n_steps, idx = _save_indices(t0, t1, dt, saveat)
    checked = rtol is not None or atol is not None
    if checked:
        rtol, atol = tolerances(rtol, atol)
    # with a tolerance the rollout also keeps the states the error estimate samples
    kept = np.union1d(idx, _sample_steps(n_steps, idx)) if checked else idx
    block = math.gcd(*kept.tolist(), n_steps)
    nq, nv = system.state_sizes()
    q0, u0 = _state(q0, "q0", nq), _state(v0, "v0", nv)
    check_unit_quaternions(q0, system.quaternions(), "q0")
    qs, us, status, fields = _rollout(system, integrator, q0, u0, float(t0), float(dt), block,
                                      n_steps // block, tuple((kept // block).tolist()),
                                      _segment(block) if checkpoint else block)
    ts = jnp.asarray(t0 + idx * dt, dtype=q0.dtype)
    new, first, by = status, fields["flagged_at"], fields["inaccurate_by"]
    all_qs, all_us, all_ts = qs, us, ts
    if checked:
        all_ts = jnp.asarray(t0 + kept * dt, dtype=q0.dtype)
        if len(kept) != len(idx):
            at = np.searchsorted(kept, idx)
            qs, us = all_qs[at], all_us[at]
        # the samples: the start and the kept states before t1, at most ERROR_SAMPLES, spread out
        before = np.flatnonzero((kept > 0) & (kept < n_steps))
        picks = before[sample_indices(len(before))]
        starts = (jnp.concatenate([q0[None], all_qs[picks]]),
                  jnp.concatenate([u0[None], all_us[picks]]),
                  jnp.concatenate([jnp.asarray([t0], q0.dtype), all_ts[picks]]))
        error, ratio = _error_estimate(system, integrator, *starts, float(dt), n_steps, rtol,
                                       atol)
        estimated = ratio > 1.0
        new = status | jnp.where(estimated, int(Status.INACCURATE), 0).astype(status.dtype)
        # the estimate is of the final state's error: at t1 unless raised before
        first = _raised(first, status, new, jnp.asarray(t1, q0.dtype))
        by = by | jnp.where(estimated, ESTIMATED, 0)
        fields.update(error=error)
    # the invariants' drift: held to rtol where a tolerance is given (rtol = 0: reported, not
    # held), else to DEFAULT_DRIFT_LIMIT; a check, not differentiated
    limit = rtol if checked else DEFAULT_DRIFT_LIMIT
    drift = _drift(system, jnp.asarray(t0, q0.dtype), q0, u0, all_ts, all_qs, all_us, limit)
    if drift is not None:
        (value, which, when), names = drift
        drifted = (value > limit) & (limit > 0)
        status, new = new, new | jnp.where(drifted, int(Status.INACCURATE), 0).astype(new.dtype)
        first = _raised(first, status, new, when)
        by = by | jnp.where(drifted, DRIFTED, 0)
        fields.update(drift=value, drifting=which, invariant_names=names)
    fields.update(flagged_at=first, inaccurate_by=by)
    return raise_on_failure(Solution(ts=ts, qs=qs, vs=us, status=new, **fields), throw,
                            "mbjax.simulate")


@eqx.filter_jit
def _error_estimate(system, integrator, q, u, t, dt: float, n_steps: int, rtol, atol):
    """(estimated global error, its ratio to the tolerance) from step doubling at the sampled
    states (q, u, t) (see `simulate`)."""
    p = integrator.order

    def step(state, t, h):
        q, u = state
        return integrator.advance(system, t, q, u, h)[:2]

    def local(q, u, t):
        h = jnp.asarray(dt, q.dtype)
        full, _, half = doubled(step, (q, u), t, h, h)
        full = jnp.concatenate(full)
        e = (full - jnp.concatenate(half)) * (2.0**p / (2.0**p - 1.0))
        scale = atol + rtol * jnp.maximum(jnp.abs(jnp.concatenate([q, u])), jnp.abs(full))
        return jnp.max(jnp.abs(e)), jnp.sqrt(jnp.mean((e / scale) ** 2))

    errors, ratios = jax.vmap(local)(q, u, t)
    return n_steps * jnp.mean(errors), n_steps * jnp.mean(ratios)


def _drift(system, t0, q0, u0, ts, qs, us, limit: float):
    """((the invariants' largest relative drift over the start (t0, q0, u0) and the states (ts,
    qs, us), the index of the invariant, the first time it exceeds `limit` or NaN), their
    names), or None for a system that knows none (`mbjax._src.system.invariants.drifts`); a
    limit of 0 holds it to nothing. A check, not differentiated.

    The check's program runs for about a microsecond a state: called at the top level on the
    CPU, XLA compiles it without its backend optimizations, three times faster for a run about
    2.7 times slower (benchmarks/README.md, the accuracy section); JAX takes compiler options
    at the top level only, so under jit, vmap or grad the check compiles with the program
    around it."""
    traced = any(isinstance(x, jax.core.Tracer)
                 for x in jax.tree.leaves((system, t0, q0, u0, ts, qs, us)))
    fast = not traced and jax.default_backend() == "cpu"
    return (_drift_top if fast else _drift_nested)(system, t0, q0, u0, ts, qs, us, limit)


def _drift_of(system, t0, q0, u0, ts, qs, us, limit: float):
    """`_drift`, to be compiled."""
    if system.invariants(t0, q0, u0) is None:
        return None
    system = jax.tree.map(lambda x: jax.lax.stop_gradient(x) if eqx.is_array(x) else x, system)
    ts, qs, us = jax.lax.stop_gradient((jnp.concatenate([t0[None], ts]),
                                        jnp.concatenate([q0[None], qs]),
                                        jnp.concatenate([u0[None], us])))
    history = jax.vmap(system.invariants)(ts, qs, us)
    ratios = drifts(history)                                    # (T, k)
    over = (jnp.max(ratios, axis=1) > limit) & (limit > 0)
    when = jnp.where(jnp.any(over), ts[jnp.argmax(over)], jnp.nan)
    return ((jnp.max(ratios, initial=0.0), jnp.argmax(jnp.max(ratios, axis=0)), when),
            history.labels())


_drift_top = eqx.filter_jit(_drift_of, compiler_options={"xla_backend_optimization_level": 0})
_drift_nested = eqx.filter_jit(_drift_of)


def _sample_steps(n_steps: int, idx: np.ndarray) -> np.ndarray:
    """Steps inside the run where the error estimate samples the state when the saved ones are
    too sparse for it (fewer than about ERROR_SAMPLES along the run): multiples of the largest
    divisor d of the saves' common step count with d <= n_steps / ERROR_SAMPLES, so that the
    rollout's blocks stay whole; none where the saves are dense enough, or where no such
    divisor is within a factor 8 of that spacing (the saved states then serve alone)."""
    spacing = max(n_steps // ERROR_SAMPLES, 1)
    common = math.gcd(*idx.tolist(), n_steps)
    if common <= spacing:
        return np.zeros(0, int)
    d = max(k for k in range(1, spacing + 1) if common % k == 0)
    if 8 * d < spacing:
        return np.zeros(0, int)
    return np.arange(d, n_steps, d)


def _segment(block: int) -> int:
    """The divisor of `block` nearest sqrt(block) from below: the checkpointed segment length."""
    return max(k for k in range(1, math.isqrt(block) + 1) if block % k == 0)


class _Watch(NamedTuple):
    """What the rollout carries for its status besides the flags: the last increments of the
    state's parts and their steps in motion (`step_ratio`), the last ratios, the largest held
    one, the time each flag was first raised, and what first tripped the system's check."""

    increment: tuple
    moved: tuple
    recent: Array
    worst: Array
    first: Array
    culprit: Array


def _raised(first: Array, old: Array, new: Array, t: Array) -> Array:
    """The times each flag was first raised (shape status + (8,)), with those `new` raises over
    `old` at t."""
    bits = jnp.asarray([int(f) for f in FLAGS], jnp.int32)
    return jnp.where(((new[..., None] & bits) != 0) & ((old[..., None] & bits) == 0), t, first)


@eqx.filter_jit
def _rollout(system, integrator, q0, u0, t0, dt, block: int, n_blocks: int, keep: tuple,
             segment: int):
    """(saved qs, us, status, the default check's `Solution` fields): the steps with the
    resolution watched at every step, the system's check at the block ends."""
    dtype = q0.dtype
    t0, dt = jnp.asarray(t0, dtype), jnp.asarray(dt, dtype)
    inaccurate = jnp.asarray(int(Status.INACCURATE), jnp.int32)
    # one status per copy for a batched system (its copies along the state's last axis)
    members = q0.shape[-1:] if system.batched else ()

    def flat(q, u):
        """The state's parts as columns (one per copy), not differentiated."""
        return tuple(jax.lax.stop_gradient(x.reshape(-1, *members)) for x in (q, u))

    def step(carry, k):
        q, u, status, watch = carry
        t = t0 + k * dt
        # sampled controls take their value at the step's start for all of its stages
        q1, u1, converged = integrator.advance(system, t, q, u, dt)
        y0, y1 = flat(q, u), flat(q1, u1)
        finite = jnp.all(jnp.isfinite(y1[0]), axis=0) & jnp.all(jnp.isfinite(y1[1]), axis=0)
        # the default check: the step times the motion's rate, from consecutive increments
        increment = tuple(b - a for a, b in zip(y0, y1))
        r, moved = step_ratio(watch.increment, increment, y0, watch.moved)
        held = jnp.minimum(r, jnp.min(watch.recent, axis=0))     # over SUSTAINED steps
        new = (status | jnp.where(finite, 0, int(Status.NONFINITE))
               | jnp.where(converged, 0, int(Status.NOT_CONVERGED))
               | jnp.where(held > RESOLUTION_LIMIT, inaccurate, 0))
        watch = watch._replace(increment=increment, moved=moved,
                               recent=jnp.concatenate([watch.recent[1:], r[None]]),
                               worst=jnp.fmax(watch.worst, held),
                               first=_raised(watch.first, status, new, t + dt))
        return (q1, u1, new, watch), None

    def run_segment(carry, ks):
        return jax.lax.scan(step, carry, ks)[0], None

    def checked(t, q, u, status, watch):
        """The status and watch with the system's check at a state (not differentiated)."""
        q, u = jax.lax.stop_gradient(q), jax.lax.stop_gradient(u)
        flags = system.check(t, q, u).astype(jnp.int32)
        culprit = jnp.where((watch.culprit < 0) & (flags != 0), system.culprit(t, q, u),
                            watch.culprit)
        new = status | flags
        return new, watch._replace(first=_raised(watch.first, status, new, t), culprit=culprit)

    def run_block(carry, b):
        ks = b * block + jnp.arange(block)
        if segment < block:                  # checkpoint=True: only segment ends are kept
            carry, _ = jax.lax.scan(jax.checkpoint(run_segment), carry,
                                    ks.reshape(block // segment, segment))
        else:
            carry, _ = run_segment(carry, ks)
        q, u, status, watch = carry
        status, watch = checked(t0 + (b + 1) * block * dt, q, u, status, watch)
        return (q, u, status, watch), (q, u)

    # the start is a saved state too: the system's check sees it (a start on a singularity)
    zero = jnp.zeros(members, dtype)
    watch = _Watch(increment=jax.tree.map(jnp.zeros_like, flat(q0, u0)),
                   moved=(jnp.zeros(members, jnp.int32),) * 2,
                   recent=jnp.zeros((SUSTAINED - 1, *members), dtype), worst=zero,
                   first=jnp.full((*members, len(FLAGS)), jnp.nan, dtype),
                   culprit=jnp.full(members, -1, jnp.int32))
    init = (q0, u0, *checked(t0, q0, u0, jnp.zeros(members, jnp.int32), watch))
    # Scans nest (blocks, segments, steps, an integrator's stages), and reverse mode traces a
    # scan's body several times per level: a level of length one is a plain call instead.
    if n_blocks == 1:
        final, (q, u) = run_block(init, 0)
        qs, us = q[None], u[None]
    else:
        final, (qs, us) = jax.lax.scan(run_block, init, jnp.arange(n_blocks))
    status, watch = final[2], final[3]
    qs = jnp.concatenate([q0[None], qs])[jnp.array(keep)]
    us = jnp.concatenate([u0[None], us])[jnp.array(keep)]
    return qs, us, status, dict(resolution=watch.worst, flagged_at=watch.first,
                                culprit=watch.culprit, culprit_names=system.culprit_names(),
                                inaccurate_by=jnp.where(status & int(Status.INACCURATE), RESOLVED,
                                                        0))
