"""The status every run reports: `Status` flags, results that carry them, and the error a
failed run raises when asked to (throw=True)."""

import collections
import enum

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jax import Array


class Status(enum.IntFlag):
    """Flags OR-ed into a result's `status` (`Solution.status`, one per run; batched under
    vmap), an integer array that prints in words (`Flags<limit exceeded>`); 0 means success
    without remarks. Test a flag with `status & Status.X`, and a run with `result.ok`;
    `result.messages()` spells the flags out with their causes.

    Attributes:
        SUCCESS: 0, no flag set.
        NONFINITE: a state became inf or NaN (the step is beyond the method's stability).
        NOT_CONVERGED: an implicit step's Newton iteration missed its tolerance.
        SOLVER_FAILED: the adaptive reference solver stopped (step-size underflow, max_steps).
        CONSTRAINT_VIOLATED: a closed loop's residual |Phi| grew past the system's tolerance.
        REDUNDANT: a note, not a failure: the constraint Jacobian lost rank (redundant closures
            or a singular configuration); least-squares loads were used.
        LIMIT_EXCEEDED: a note: a saved state or control is beyond the model's joint limits
            (position, velocity or effort: `Model.lower`, `upper`, `velocity_limit`,
            `effort_limit`).
        INACCURATE: the steps do not resolve the motion (the default check,
            `Solution.resolution` above 1), the invariants' drift (`Solution.drift`) exceeds
            the tolerance asked for (rtol) or by default a bound (1 % of the motion's scale in
            `simulate`, 10 % in `solve_tfe`), or the estimated error exceeds the tolerance
            (`simulate`'s rtol and atol; `Solution.error`).
        SINGULAR: a saved state at (or within the system's tolerance of) a singular
            configuration, where the dynamics are not defined (the Carpal Wrist's inverse or
            direct singularity: `WristSystem.check`).
        PULLING: a contact held on the ground pulls on it (a negative normal force): the foot
            would have lifted off (`mbjax.contact.stance` with a friction coefficient).
        SLIPPING: a contact's force leaves its friction cone: the foot would have slipped.
        PENETRATING: a contact found by `mbjax.contact.ContactSystem` sinks deeper than the
            system's `penetration` bound: the steps or the contact's softness let a body
            pass through another.
        UNRESOLVED: a pushing contact's or joint limit's time constant is shorter than two
            of the system's steps (a `solref` below MuJoCo's safety bound, with
            `SoftConstraints(refsafe=False)` or a direct stiffness and damping): the steps
            cannot follow its transient, and the contact's motion is the integrator's, not the
            model's.
    """

    SUCCESS = 0
    NONFINITE = 1
    NOT_CONVERGED = 2
    SOLVER_FAILED = 4
    CONSTRAINT_VIOLATED = 8
    REDUNDANT = 16
    LIMIT_EXCEEDED = 32
    INACCURATE = 64
    SINGULAR = 128
    PULLING = 256
    SLIPPING = 512
    PENETRATING = 1024
    UNRESOLVED = 2048

    @classmethod
    def failures(cls) -> int:
        """The flags that make a run fail (`REDUNDANT` and `LIMIT_EXCEEDED` only inform).

        Returns:
            The failure flags OR-ed into one int mask.
        """
        return (cls.NONFINITE | cls.NOT_CONVERGED | cls.SOLVER_FAILED | cls.CONSTRAINT_VIOLATED
                | cls.INACCURATE | cls.SINGULAR | cls.PULLING | cls.SLIPPING | cls.PENETRATING
                | cls.UNRESOLVED)


# the flags in order: `flagged_at` keeps the time each was first raised
FLAGS = tuple(flag for flag in Status if flag)


def _code(other):
    return other.code if isinstance(other, Flags) else other


class Flags(eqx.Module):
    """A result's `status`: `Status` flags OR-ed into an integer array (one per run, batched
    under vmap) that prints in words (`Flags<limit exceeded>`), as diffrax's `RESULTS` does, and
    still computes as the integer array: `status & Status.X`, `status == 0`, `int(status)`,
    `jnp.where(..., status, ...)` and `np.asarray(status)` under jit and vmap alike.

    Args:
        code: the flags, an integer array (or `Flags`).
    """

    code: Array

    def __init__(self, code):
        code = jnp.asarray(_code(code))
        self.code = code if jnp.issubdtype(code.dtype, jnp.integer) else code.astype(jnp.int32)

    def __jax_array__(self) -> Array:
        return self.code

    def __array__(self, dtype=None, copy=None) -> np.ndarray:
        return np.asarray(self.code, dtype=dtype)

    def __and__(self, other) -> Array:
        return self.code & _code(other)

    __rand__ = __and__

    def __or__(self, other) -> "Flags":
        return Flags(self.code | _code(other))

    __ror__ = __or__

    def __eq__(self, other) -> Array:
        return self.code == _code(other)

    def __ne__(self, other) -> Array:
        return self.code != _code(other)

    __hash__ = None

    def __int__(self) -> int:
        return int(self.code)

    __index__ = __int__

    def __bool__(self) -> bool:
        return bool(self.code)

    def __getitem__(self, index) -> "Flags":
        return Flags(self.code[index])

    def __len__(self) -> int:
        return len(self.code)

    def __iter__(self):
        return (self[i] for i in range(len(self)))

    @property
    def shape(self) -> tuple:
        return self.code.shape

    @property
    def ndim(self) -> int:
        return self.code.ndim

    @property
    def dtype(self):
        return self.code.dtype

    def astype(self, dtype) -> "Flags":
        return Flags(self.code.astype(dtype))

    def item(self) -> int:
        return int(self.code)

    def tolist(self):
        return np.asarray(self.code).tolist()

    def __repr__(self) -> str:
        if isinstance(self.code, jax.core.Tracer):
            return f"Flags<{self.code.aval.str_short()}>"
        codes = np.asarray(self.code)
        if codes.ndim == 0:
            return f"Flags<{describe(int(codes), {})}>"
        words = [describe(int(c), {}) for c in codes.ravel()]
        return f"Flags<shape {codes.shape}: " + "; ".join(words) + ">"

    __str__ = __repr__


def flags(code) -> Flags:
    """code as `Flags` (a result's status field converter)."""
    return code if isinstance(code, Flags) else Flags(code)


def raise_on_failure(result, throw: bool, who: str):
    """`result` (a `WithStatus`) as it is, or, with throw=True, an error (`eqx.error_if`, so also
    under jit and vmap) naming the first failure flag set in its status, as diffrax's
    throw=True does; the default returns the status for the caller to read."""
    if not throw:
        return result
    failures = [flag for flag in Status if flag & Status.failures()]
    failed = (result.status & Status.failures()) != 0
    first = jnp.argmax(jnp.stack([(result.status & flag) != 0 for flag in failures]), axis=0)
    messages = [f"{who}: the run failed with status {flag.name.lower().replace('_', ' ')} "
                f"({flag.value}; throw=False returns the result with its status instead)"
                for flag in failures]
    return eqx.branched_error_if(result, jnp.any(failed), jnp.max(first), messages)


class WithStatus(eqx.Module):
    """A result carrying an integer `status` array of `Status` flags (one per run; batched under
    vmap)."""

    @property
    def ok(self) -> Array:
        """True where the run succeeded (no failure flag; the notes only inform); the shape of
        `status`."""
        return (self.status & Status.failures()) == 0

    def messages(self) -> list[str]:
        """Human-readable status for each (possibly batched) run; needs concrete values.

        Each flag is spelled out with what tripped it where the result knows (the time a flag
        was first raised, the measure that found a run inaccurate, the invariant that drifted).

        Returns:
            One string per run ("success", or the flags' names joined by commas, each with its
            particulars in parentheses), in the order of `status` flattened.
        """
        codes = np.atleast_1d(np.asarray(self.status)).ravel()
        return [describe(int(code), self.notes(i)) for i, code in enumerate(codes)]

    def notes(self, i: int) -> dict:
        """{flag: what tripped it} for the i-th run (flattened); none by default."""
        return {}

    def __str__(self) -> str:
        """The status in words, as `print(result)` shows it: "Solution: success", or each flag
        with its cause (`messages()`); a batch counts its runs per message."""
        if isinstance(_code(self.status), jax.core.Tracer):
            return repr(self)
        words = self.messages()
        if len(words) == 1:
            return f"{type(self).__name__}: {words[0]}"
        counts = collections.Counter(words)
        return (f"{type(self).__name__}, {len(words)} runs: "
                + "; ".join(f"{n} {word}" for word, n in counts.most_common()))


def describe(code: int, notes: dict) -> str:
    """A status in words: the flags set in `code` by name, each followed by its note."""
    words = [flag.name.lower().replace("_", " ") + (f" ({notes[flag]})" if notes.get(flag) else "")
             for flag in Status if flag and code & flag]
    return ", ".join(words) or "success"


def run_member(result, x, i: int):
    """The i-th (flattened) run's value of a field x of a possibly batched `result` (its
    leading axes those of its status), for the host-side messages."""
    x = np.asarray(x)
    return x.reshape(-1, *x.shape[np.ndim(result.status):])[i] if x.ndim else x


# why a run is INACCURATE (`Solution.inaccurate_by`, a mask of these)
RESOLVED, DRIFTED, ESTIMATED = 1, 2, 4


def accuracy_notes(result, i: int, flags_at=None) -> dict:
    """The notes of a result that carries the accuracy check's measures (`Solution`,
    `TFESolution`: resolution, drift, drifting, invariant_names, error, inaccurate_by) and
    optionally the time each flag was first raised, for its i-th (flattened) run."""
    def member(x):
        return run_member(result, x, i)

    notes = {}
    if flags_at is not None:
        at = member(flags_at)
        for k, flag in enumerate(FLAGS):
            if np.isfinite(at[k]):
                notes[flag] = f"first at t = {at[k]:.4g} s"
    culprit = int(member(getattr(result, "culprit", -1)))
    names = getattr(result, "culprit_names", ())
    raised = [flag for flag in (Status.LIMIT_EXCEEDED, Status.SINGULAR)
              if int(member(result.status)) & flag]
    if 0 <= culprit < len(names) and raised:
        # the system's check names what it found (`AbstractSystem.culprit`)
        notes[raised[0]] = "; ".join(filter(None, (names[culprit], notes.get(raised[0]))))
    by = int(member(result.inaccurate_by))
    reasons = []
    if by & RESOLVED:
        reasons.append(f"the steps do not resolve the motion: step x rate reached "
                       f"{float(member(result.resolution)):.3g} > 1")
    if by & DRIFTED:
        k = int(member(result.drifting))
        name = result.invariant_names[k] if 0 <= k < len(result.invariant_names) else "invariant"
        reasons.append(f"the {name} drifted by {float(member(result.drift)):.3g} of its scale")
    if by & ESTIMATED:
        reasons.append(f"estimated error {float(member(result.error)):.3g} beyond the tolerance")
    if reasons:
        notes[Status.INACCURATE] = "; ".join(reasons + ([notes[Status.INACCURATE]]
                                                        if Status.INACCURATE in notes else []))
    return notes
