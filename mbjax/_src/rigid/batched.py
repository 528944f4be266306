"""Forward dynamics of many states at once: Anderson 1993's O(n) recursion (§2.3) laid out for throughput.

`aba` (mbjax._src.rigid.aba) is written for one state, in ground coordinates, with general motion
subspaces and 6x6 blocks; `jax.vmap` of it puts the batch first and leaves XLA many tiny matrix
products per state. `batch_aba` runs the same three passes for B states at once, written for the
CPU's vector units and XLA's fusion:

- structure of arrays: every scalar of the recursion (a component of a 3-vector, of a 3x3 block)
  is one array over the batch, and the 3- and 6-vectors are Python tuples of them. A step of a
  pass is then one straight-line program of elementwise operations on B-long arrays, which XLA
  fuses into a few loops whose intermediates stay in registers: no `dot_general`, no reduce, no
  concatenate;
- body coordinates (Featherstone's form of the recursion, X the parent-to-child transform): a
  1-DOF joint's motion subspace is then a constant unit vector s, (a; 0) for a revolute joint about
  a, (0; a) for a prismatic one (joint-axis sparsity), so U = I_2 s, D = s.U and S u_dot are
  products with constants, and the remainder acceleration of eqs 29-31 is c = V x (s v);
- the articulated inertia handed to the parent (X^T I_3 X, Anderson 1993 eqs 45-50) in 3x3 blocks: a
  rotation, then a shift of origin by cross products;
- `mbjax.tree`'s passes (a carry-only scan for a chain, a scan over bodies or depth levels for a
  tree), so compile time stays flat in n;
- the angular and linear blocks A and M of an (articulated) inertia are symmetric: their upper
  triangles are computed and mirrored, the lower entries being the same arrays;
- the joint angles' sines and cosines are computed for the whole batch before the passes, by
  `lie.sincos` (XLA calls the C library's for `jnp.sin` element by element, slowest inside a
  loop compiled as one kernel).

The last two are the largest single gains (the timings are in benchmarks/README.md).

The passes, per body k with parent p (Anderson 1993 eqs 20-31, 48-50, 80-84):

    (i)   V_k = X_k V_p + s_k v_k,      c_k = V_k x (s_k v_k),      F_1 = V_k x* (I_k V_k)
    (ii)  U = I_2 s,  D = s.U,  u = tau - s.F_2,  I_3 = I_2 - U U^T / D,  F_3 = F_2 + I_3 c + U u / D;
          the parent receives X^T I_3 X and X^T F_3
    (iii) a' = X_k a_p + c_k,  u_dot = (u - U.a') / D,  a_k = a' + s_k u_dot,  a_ground = (0; -g)

Revolute and prismatic joints only (one constant subspace column each); other joints raise. The
arithmetic follows q's dtype, so float32 runs in float32 throughout.
"""

import jax
import jax.numpy as jnp
import numpy as np
from jax import Array

from mbjax._src import lie, runtime
from mbjax._src.model import Model
from mbjax._src.tree import backward_pass, forward_pass

JOINTS = ("revolute", "prismatic")
# Where XLA compiles a loop as one kernel (`mbjax._src.runtime.hoisting`), a batch runs as a loop over
# chunks of CHUNK states, so that each chunk's intermediates stay in cache (faster than one kernel
# for the whole batch and than larger chunks; benchmarks/README.md). With kernels launched one by
# one, the whole batch at once is faster.
CHUNK = 64

# -- structure-of-arrays algebra: a 3-vector is a tuple of 3 arrays, a 3x3 matrix a tuple of rows,
#    a spatial vector a pair (angular, linear), a spatial inertia its blocks (A, B, M) --------------


def _add(a, b):
    return tuple(x + y for x, y in zip(a, b, strict=True))


def _sub(a, b):
    return tuple(x - y for x, y in zip(a, b, strict=True))


def _scale(a, k):
    return tuple(x * k for x in a)


def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _tr(M):
    return tuple(zip(*M, strict=True))


def _mv(M, x):
    return tuple(_dot(row, x) for row in M)


def _mtv(M, x):
    return _mv(_tr(M), x)


def _mm(A, C):
    columns = _tr(C)
    return tuple(tuple(_dot(row, col) for col in columns) for row in A)


def _madd(A, C):
    return tuple(_add(a, c) for a, c in zip(A, C, strict=True))


def _outer(a, b, k):
    """a b^T k."""
    return tuple(tuple(x * y * k for y in b) for x in a)


def _p_times(p, M):
    """p~ M, column by column: p x M[:, j]."""
    return _tr(tuple(_cross(p, col) for col in _tr(M)))


def _times_p(M, p):
    """M p~, row by row: M[i, :] x p."""
    return tuple(_cross(row, p) for row in M)


def _inertia_times(I, m):  # noqa: E741 (the papers' name)
    (A, B, M), (w, v) = I, m
    return _add(_mv(A, w), _mv(B, v)), _add(_mtv(B, w), _mv(M, v))


def _cross_motion(m, x):
    """m x x for spatial motion vectors (angular; linear)."""
    (w, v), (xw, xv) = m, x
    return _cross(w, xw), _add(_cross(w, xv), _cross(v, xw))


def _cross_force(m, f):
    """m x* f for a motion m and a force f (moment; force)."""
    (w, v), (n, f) = m, f
    return _add(_cross(w, n), _cross(v, f)), _cross(w, f)


def _sdot(s, x):
    return _dot(s[0], x[0]) + _dot(s[1], x[1])


# -- the parent-to-child transform X = (R, p): body k's orientation and origin in its parent --------


def _motion_to_child(R, p, m):
    """X m = (R^T w; R^T (v - p x w))."""
    w, v = m
    return _mtv(R, w), _mtv(R, _sub(v, _cross(p, w)))


def _force_to_parent(R, p, f):
    """X^T f = (R n + p x R f; R f)."""
    force = _mv(R, f[1])
    return _add(_mv(R, f[0]), _cross(p, force)), force


def _symmetric(M):
    """M's upper triangle, mirrored: the lower entries are the upper ones' arrays."""
    return tuple(tuple(M[min(i, j)][max(i, j)] for j in range(3)) for i in range(3))


def _rotate_symmetric(R, S):
    """R S R^T of a symmetric S, its upper triangle computed."""
    RS = _mm(R, S)
    return _symmetric(tuple(tuple(_dot(RS[i], R[j]) if j >= i else None for j in range(3))
                            for i in range(3)))


def _inertia_to_parent(R, p, I):  # noqa: E741
    """X^T I X in blocks: rotate [[A, B], [B^T, M]] to the parent's axes, then shift its origin by
    p (P = p~): A' = A + P B^T + (P B^T)^T - P M P, B' = B + P M, M' = M."""
    A, B, M = I
    A, M = _rotate_symmetric(R, A), _rotate_symmetric(R, M)
    B = _mm(_mm(R, B), _tr(R))
    PM, PBt = _p_times(p, M), _p_times(p, _tr(B))
    A = _madd(_madd(A, PBt), _tr(PBt))
    A = tuple(_sub(a, x) for a, x in zip(A, _times_p(PM, p), strict=True))
    return _symmetric(A), _madd(B, PM), M


# -- joints ---------------------------------------------------------------------------------------


def _check_joints(model: Model) -> np.ndarray:
    """Static (n,) mask of the revolute joints; raises for a joint with other than one column."""
    bad = sorted({kind for kind in model.joint_types if kind not in JOINTS})
    if bad:
        raise ValueError(f"batch_aba runs trees of {' and '.join(JOINTS)} joints (one constant "
                         f"motion-subspace column each); this model has {', '.join(bad)} joints: "
                         "use jax.vmap(mbjax.rigid.forward_dynamics) for it")
    return np.array([kind == "revolute" for kind in model.joint_types])


def _vec(x: Array):
    """(n, 3) per-body constants -> a 3-vector of (n, 1) arrays (they broadcast over the batch)."""
    return tuple(x[:, i, None] for i in range(3))


def _mat(x: Array):
    return tuple(tuple(x[:, i, j, None] for j in range(3)) for i in range(3))


def _joint_transforms(model: Model, revolute: np.ndarray, q: Array, sin: Array, cos: Array):
    """(R, p, s) for q (n, B) and the sine and cosine of the revolute joints' angles (0 and 1 for
    the prismatic ones): every body's orientation R and origin p in its parent (placement times
    joint motion, as `Model.joints`) and its motion subspace s in body coordinates; `revolute` is
    `_check_joints`'s mask."""
    revolute = jnp.asarray(revolute)[:, None]
    a = _vec(model.axis)
    zero = jnp.zeros_like(a[0])
    versine = 1.0 - cos
    K = ((zero, -a[2], a[1]), (a[2], zero, -a[0]), (-a[1], a[0], zero))
    KK = _mm(K, K)
    eye = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
    R_joint = tuple(tuple(e + sin * k + versine * kk for e, k, kk in zip(*rows, strict=True))
                    for rows in zip(eye, K, KK, strict=True))        # Rodrigues; I if prismatic
    Rp = _mat(model.placement_rotation)
    slide = _scale(a, jnp.where(revolute, 0.0, q))
    p = _add(_vec(model.placement_translation), _mv(Rp, slide))
    s_angular = tuple(jnp.where(revolute, x, 0.0) for x in a)
    s_linear = tuple(jnp.where(revolute, 0.0, x) for x in a)
    return _mm(Rp, R_joint), p, (s_angular, s_linear)


# -- the recursion --------------------------------------------------------------------------------


def batch_aba(model: Model, q: Array, v: Array, tau: Array) -> Array:
    """Joint accelerations (n, B) of B states (q, v, tau), each (n, B), batch last; gravity from
    the model. tau may also be (n,) or (n, 1), the same for every state.

    Where XLA compiles a loop as one kernel (`mbjax._src.runtime.hoisting`), a batch of more than
    CHUNK states runs as a loop over chunks of CHUNK, so that each chunk's intermediates stay in
    cache (see CHUNK)."""
    revolute = _check_joints(model)
    q = jnp.asarray(q)
    if q.ndim != 2 or q.shape[0] != model.nv:
        raise ValueError(f"batch_aba takes (nv, B) = ({model.nv}, B) arrays, batch last; got q of "
                         f"shape {q.shape} (see batched_forward_dynamics for (B, nv))")
    dtype, (n, batch) = q.dtype, q.shape
    v = jnp.broadcast_to(jnp.asarray(v, dtype), q.shape)
    tau = jnp.broadcast_to(jnp.reshape(jnp.asarray(tau, dtype), (n, -1)), q.shape)
    # outside the chunk loop, vectorized (`lie.sincos`): inside it XLA calls the C library's sin
    # and cos element by element, a large part of a state's cost (benchmarks/README.md)
    sin, cos = lie.sincos(jnp.where(jnp.asarray(revolute)[:, None], q, 0.0))
    if not runtime.HOISTING or batch <= CHUNK:
        return _chunk(model, revolute, q, v, tau, sin, cos)
    chunks = -(-batch // CHUNK)

    def split(x):                 # (nv, B) -> (chunks, nv, CHUNK), the last padded by repeats
        x = jnp.pad(x, ((0, 0), (0, chunks * CHUNK - batch)), mode="edge")
        return jnp.moveaxis(x.reshape(n, chunks, CHUNK), 1, 0)

    out = jax.lax.map(lambda x: _chunk(model, revolute, *x),
                      tuple(split(x) for x in (q, v, tau, sin, cos)))
    return jnp.moveaxis(out, 0, 1).reshape(n, -1)[:, :batch]


def _chunk(model: Model, revolute: np.ndarray, q: Array, v: Array, tau: Array, sin: Array,
           cos: Array) -> Array:
    """`batch_aba` of (n, B) arrays as one straight-line program per step of each pass."""
    dtype, (n, batch) = q.dtype, q.shape
    model = jax.tree.map(lambda x: x.astype(dtype) if jnp.issubdtype(x.dtype, jnp.floating) else x,
                         model)
    tau = (tau - model.damping[:, None] * v                 # joint damping and springs
           - model.stiffness[:, None] * (q - model.spring_reference[:, None]))
    R, p, s = _joint_transforms(model, revolute, q, sin, cos)
    sv = (_scale(s[0], v), _scale(s[1], v))
    inertia = model.spatial_inertia()
    blocks = (_symmetric(_mat(inertia[:, :3, :3])), _mat(inertia[:, :3, 3:]),
              _symmetric(_mat(inertia[:, 3:, 3:])))
    zeros = jnp.zeros(batch, dtype)

    # (i) velocities, outward
    def velocity(V_parent, x):
        R, p, sv = x
        Xv = _motion_to_child(R, p, V_parent)
        return _add(Xv[0], sv[0]), _add(Xv[1], sv[1])

    V = forward_pass(model.topology, velocity, ((zeros,) * 3, (zeros,) * 3), (R, p, sv))
    c = _cross_motion(V, sv)
    F1 = _cross_force(V, _inertia_times(blocks, V))

    # (ii) articulated inertias and forces, inward
    def triangularize(received, x):
        (IA, pA), (R, p, s, c, t, armature) = received, x
        U = _inertia_times(IA, s)
        D = _sdot(s, U) + armature
        u = t - _sdot(s, pA)
        inv_D = 1.0 / D
        A, B, M = (_madd(block, _outer(Ui, Uj, -inv_D))
                   for block, (Ui, Uj) in zip(IA, ((U[0], U[0]), (U[0], U[1]), (U[1], U[1])),
                                             strict=True))
        Ia = _symmetric(A), B, _symmetric(M)
        Ic = _inertia_times(Ia, c)
        pa = tuple(_add(_add(f, g), _scale(w, u * inv_D))
                   for f, g, w in zip(pA, Ic, U, strict=True))
        return (U, D, u), (_inertia_to_parent(R, p, Ia), _force_to_parent(R, p, pa))

    full = jax.tree.map(lambda x: jnp.broadcast_to(x, (n, batch)), blocks)
    (U, D, u), _ = backward_pass(model.topology, triangularize, (full, F1),
                                 (R, p, s, c, tau, model.armature))

    # (iii) accelerations, outward
    def substitute(parent, x):
        (a_parent, _), (R, p, s, c, U, D, u) = parent, x
        Xa = _motion_to_child(R, p, a_parent)
        a_prime = _add(Xa[0], c[0]), _add(Xa[1], c[1])
        u_dot = (u - _sdot(U, a_prime)) / D
        return (_add(a_prime[0], _scale(s[0], u_dot)), _add(a_prime[1], _scale(s[1], u_dot))), u_dot

    g = model.gravity
    ground = (((zeros,) * 3, tuple(zeros - g[i] for i in range(3))), zeros)
    _, u_dot = forward_pass(model.topology, substitute, ground, (R, p, s, c, U, D, u))
    return u_dot


def batched_forward_dynamics(model: Model, q: Array, v: Array, tau: Array) -> Array:
    """`mbjax.forward_dynamics` of B states at once, in the throughput layout (batch last inside).

    Anderson 1993's O(n) recursion (§2.3) with every scalar an array over the batch
    (`batch_aba`, laid out as docs/details.md says); agrees with
    `jax.vmap(mbjax.forward_dynamics)` to rounding, which takes this route by itself for large
    batches. Gravity comes from the model; no external wrenches. The arithmetic follows q's dtype.

    Args:
        model: a tree of revolute and prismatic joints only (nq = nv).
        q: configurations, shape (B, nv).
        v: joint velocities, shape (B, nv).
        tau: joint forces [N m or N], shape (B, nv).

    Returns:
        The joint accelerations, shape (B, nv).

    Raises:
        ValueError: q is not (B, nv), or the model has a joint other than revolute or prismatic.

    More on the layout: the documentation site's Details page (docs/details.md).
    """
    q = jnp.asarray(q)
    if q.ndim != 2 or q.shape[1] != model.nv:
        raise ValueError(f"q must be (B, nv) = (B, {model.nv}), got shape {q.shape}")
    return batch_aba(model, q.T, jnp.asarray(v).T, jnp.asarray(tau).T).T
