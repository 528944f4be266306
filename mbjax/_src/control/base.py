"""What every control is: a callable (t, q, v) -> generalized forces, and how controls combine.

A control is an equinox module, so its array leaves (gains, knots, weights) can be differentiated,
vmapped and swept like a model's parameters. `hold(t, q, v)` says what the control is over one
step of `mbjax.simulate` that starts at (t, q, v): itself for a law of continuous time, the value
at the step's start for a sampled one (`ZeroOrderHold`, `SampleAndHold`: MuJoCo's `ctrl`, held
over the step's stages).
"""

import abc
from collections.abc import Callable

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jax import Array


class AbstractControl(eqx.Module):
    """A control law tau = control(t, q, v) on a system's actuated velocity coordinates.

    Subclasses implement `__call__`, and `hold` where the control is sampled. Controls add:
    `a + b` is `Sum((a, b))`, and a callable or a constant array on either side is wrapped
    first.
    """

    @abc.abstractmethod
    def __call__(self, t: Array, q: Array, v: Array) -> Array:
        """The generalized forces at time t and state (q, v).

        Args:
            t: time [s], a scalar.
            q: configuration, shape (nq,).
            v: generalized velocity, shape (nv,).

        Returns:
            The generalized forces on the actuated coordinates, shape (n_actuated,) (or, for
            `external=`, the world-frame wrenches, shape (n_bodies, 6)).
        """

    def hold(self, t: Array, q: Array, v: Array) -> "AbstractControl":
        """The control over one step of `mbjax.simulate` that starts at (t, q, v).

        Args:
            t: time at the step's start [s], a scalar.
            q: configuration at the step's start, shape (nq,).
            v: generalized velocity at the step's start, shape (nv,).

        Returns:
            The law itself for a law of continuous time; for a sampled one (`ZeroOrderHold`,
                `SampleAndHold`) a `Constant` holding its value at the step's start.
        """
        return self

    def __add__(self, other) -> "Sum":
        return Sum((self, as_control(other)))

    def __radd__(self, other) -> "Sum":
        return Sum((as_control(other), self))


class Constant(AbstractControl):
    """tau = value, whatever the time and state (what a constant `tau` given as a control means).

    Args:
        value (Array): the generalized forces, shape (n_actuated,) (or a scalar); a differentiable
            leaf.
    """

    value: Array

    def __init__(self, value):
        self.value = jnp.asarray(value, dtype=float)

    def __call__(self, t, q, v):
        return self.value


class Sum(AbstractControl):
    """The sum of several controls (feed-forward plus feedback, a spring plus a motor, ...).

    Also written `a + b`. Nested sums are flattened; a sum of sampled controls holds each term
    as the term does.

    Args:
        terms (Sequence[AbstractControl | Callable | Array]): the controls to add, a sequence of
            `AbstractControl`s, callables (t, q, v) -> tau or constant arrays.
    """

    terms: tuple

    def __init__(self, terms):
        flat = []
        for term in terms:
            flat.extend(term.terms if isinstance(term, Sum) else (as_control(term),))
        self.terms = tuple(flat)

    def __call__(self, t, q, v):
        # a few terms, fixed at trace time; their lengths must agree (a scalar term adds to all)
        outs = [jnp.asarray(term(t, q, v)) for term in self.terms]
        shapes = {out.shape for out in outs if out.shape != ()}
        if len(shapes) > 1:
            found = ", ".join(f"term {k} ({type(term).__name__}): {out.shape}"
                              for k, (term, out) in enumerate(zip(self.terms, outs)))
            raise ValueError(f"the terms of a Sum of controls must give forces of one length; "
                             f"got {found}")
        return sum(outs)

    def hold(self, t, q, v):
        return Sum(tuple(term.hold(t, q, v) for term in self.terms))


class Function(AbstractControl):
    """Any callable fn(t, q, v) -> tau as a control.

    Its parameters are differentiable when fn is an equinox module (a plain Python function has
    none).

    Args:
        fn: the control law, a callable (t, q, v) -> generalized forces.
    """

    fn: Callable

    def __call__(self, t, q, v):
        return self.fn(t, q, v)


class Saturated(AbstractControl):
    """A control saturated smoothly: tau = limit tanh(control(t, q, v) / limit).

    Smooth, and inside +-limit by construction, so gradient descent on the inner control's
    parameters needs no constraint.

    Args:
        control (AbstractControl | Callable | Array): the control to saturate (an `AbstractControl`,
            a callable (t, q, v) -> tau or a constant array).
        limit (float | Array): the saturation level, in the control's units (N or N m): a scalar or
            one per actuated coordinate, shape (n_actuated,); must be positive.
    """

    control: AbstractControl
    limit: Array

    def __init__(self, control, limit):
        self.control = as_control(control)
        self.limit = checked_limit(limit, "Saturated")

    def __call__(self, t, q, v):
        return saturate(self.control(t, q, v), self.limit)

    def hold(self, t, q, v):
        return Saturated(self.control.hold(t, q, v), self.limit)


def checked_limit(limit, who: str) -> Array | None:
    """A saturation level as a float array, None kept; an error naming `who`'s limit where a
    concrete one is not positive and finite (limit tanh(x / limit) is NaN at 0 and flips the
    sign below)."""
    if limit is None:
        return None
    limit = jnp.asarray(limit, dtype=float)
    try:
        value = np.asarray(limit)
    except jax.errors.TracerArrayConversionError:
        return limit
    if not np.all(np.isfinite(value) & (value > 0)):
        raise ValueError(f"{who}'s limit must be positive and finite, got {value}")
    return limit


def saturate(x: Array, limit: Array | None) -> Array:
    """limit tanh(x / limit), or x when limit is None: the one saturation every control uses.

    Args:
        x: the unsaturated values, any shape.
        limit: the saturation level, broadcastable to x, or None for none.

    Returns:
        The saturated values, x's shape.
    """
    return x if limit is None else limit * jnp.tanh(x / limit)


def as_control(control) -> AbstractControl | None:
    """A control from what a system's `control=` accepts.

    Args:
        control: None, an `AbstractControl`, any callable (t, q, v) -> tau, or a constant real
            array.

    Returns:
        None, the control itself, a `Function` of the callable or a `Constant` of the array.

    Raises:
        TypeError: control is a class rather than an instance, or an array that is not real.
    """
    if control is None or isinstance(control, AbstractControl):
        return control
    if isinstance(control, type):
        raise TypeError(f"control must be an instance, got the class {control.__name__}; "
                        f"call it first, e.g. {control.__name__}(...)")
    if callable(control):
        return Function(control)
    dtype = getattr(control, "dtype", None)
    dtype = np.asarray(control).dtype if dtype is None else dtype
    if not (np.issubdtype(dtype, np.integer) or np.issubdtype(dtype, np.floating)):
        raise TypeError(f"control must be a callable (t, q, v) -> tau or a real constant array, "
                        f"got {type(control).__name__} of dtype {dtype}")
    return Constant(control)
