"""Craig-Bampton component-mode reduction of a beam, Anderson 1993 sec. 2.2, eqs (9)-(10): x = phi q.

The body frame is clamped at the joint grid J^k (`clamped_node`), so rigid motion stays in the joint
coordinates and the modal basis holds deformation only (Anderson 1993 eqs (5)-(7) measure phi relative
to J^k; here phi is zero at J^k by construction). The basis columns are, in this order:

- fixed-interface normal modes (J^k and all interface-node dofs held), the lowest `n_modes` or those
  with angular frequency <= `cutoff`;
- constraint modes: static shape for a unit displacement of each free dof of each interface node,
  the other interface dofs held (Craig and Bampton 1968);
- static-correction modes: static shape for a unit load at each free dof of each
  `static_load_nodes` node, interface held (Anderson 1993 sec. 2.2).

With `orthonormalize=True` (default) the assembled basis is rotated by the eigenvectors of the
reduced problem (phi^T K phi, phi^T M phi), so M_r = I and K_r = diag(frequencies^2), sorted
ascending; `kinds` is then "reduced" for every column (a column mixes origins). When the basis holds
only normal modes no rotation is needed or done (kinds "normal"). With `orthonormalize=False` the
columns keep their origin in `kinds` and `frequencies` is nan for constraint and static columns.
"""

from __future__ import annotations

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from mbjax._src.flex.beam import Beam, _eigh_generalized, dof_groups, eigenmodes, free_dofs

__all__ = ["ModalBasis", "craig_bampton", "reduced"]


class ModalBasis(eqx.Module):
    """Modal shapes of a beam, x = phi q (Anderson 1993 eq (10)); built by `craig_bampton`.

    Args:
        shapes: phi in full beam dofs (zero on held dofs), shape (6N, mu).
        frequencies: angular frequency of each column [rad/s], shape (mu,) (nan for constraint
            and static columns that were not orthonormalized).
        kinds: per column "normal", "constraint", "static" or "reduced" (the kinds in
            docs/details.md); static.

    Kinds:
        "normal": a fixed-interface normal mode; "constraint": a constraint mode; "static": a
        static-correction mode (`craig_bampton` describes each). With `orthonormalize=True`
        (`craig_bampton`'s default) the assembled basis is rotated by the eigenvectors of the
        reduced problem, and `kinds` is then "reduced" for every column (a column mixes
        origins); when the basis holds only normal modes no rotation is needed or done (kinds
        "normal"). With `orthonormalize=False` the columns keep their origin in `kinds` and
        `frequencies` is nan for constraint and static columns.
    """

    shapes: jax.Array
    frequencies: jax.Array
    kinds: tuple[str, ...] = eqx.field(static=True)

    @property
    def mu(self) -> int:
        """Number of modal coordinates (columns)."""
        return self.shapes.shape[1]


def whole_nodes(who: str, name: str, nodes) -> tuple[int, ...]:
    """Node indices as ints; an error naming `name` where one is not a whole number (a
    fraction would be truncated to another node)."""
    values = np.atleast_1d(np.asarray(nodes))
    if values.dtype == bool or not (np.issubdtype(values.dtype, np.integer) or (
            np.issubdtype(values.dtype, np.floating) and np.all(np.isfinite(values))
            and np.all(values == np.round(values)))):
        raise ValueError(f"{who}: {name} must be whole node indices, got {nodes!r}")
    return tuple(int(n) for n in values)


def _nodes(name, nodes, beam, exclude=()):
    nodes = whole_nodes("craig_bampton", name, nodes)
    bad = [n for n in nodes if not 0 <= n < beam.n_nodes]
    if bad:
        raise ValueError(f"craig_bampton: {name} {bad} outside 0..{beam.n_nodes - 1}")
    if len(set(nodes)) != len(nodes):
        raise ValueError(f"craig_bampton: {name} has repeated nodes {nodes}")
    clash = sorted(set(nodes) & set(exclude))
    if clash:
        raise ValueError(f"craig_bampton: {name} {clash} are already the clamped or interface nodes")
    return nodes


def craig_bampton(beam: Beam, *, clamped_node=0, interface_nodes=(), n_modes=None, cutoff=None,
                  static_load_nodes=(), planar=None, orthonormalize=True) -> ModalBasis:
    """Craig-Bampton basis of `beam` clamped at `clamped_node` (Anderson 1993 sec. 2.2, eq (10)).

    The columns are the fixed-interface normal modes, then the constraint modes of the
    interface nodes, then the static-correction modes of `static_load_nodes` (the basis in
    docs/details.md).

    Args:
        beam: the beam.
        clamped_node (int): the node held as the body frame's joint grid J^k.
        interface_nodes (Sequence[int]): nodes whose dofs get constraint modes (where other bodies
            or cut joints attach).
        n_modes (int | None): number of fixed-interface normal modes (0 allowed); give exactly one
            of n_modes and cutoff.
        cutoff (float | None): keep the normal modes with angular frequency <= cutoff [rad/s]; needs
            concrete beam parameters, so use `n_modes` under jit/grad.
        static_load_nodes (Sequence[int]): nodes whose free dofs get static-correction modes.
        planar (str | None): None, "xy" or "xz": restrict the dofs as in `free_dofs`.
        orthonormalize (bool): rotate the assembled basis so that M_r = I and K_r =
            diag(frequencies^2), ascending (kinds then all "reduced").

    Returns:
        The `ModalBasis`.

    Raises:
        ValueError: both or neither of n_modes and cutoff, nodes outside the beam or repeated,
            an empty basis, no interior dofs, or (orthonormalized) linearly dependent columns.

    More on the basis: the documentation site's Details page (docs/details.md).
    """
    if (n_modes is None) == (cutoff is None):
        raise ValueError("craig_bampton: give exactly one of n_modes or cutoff")
    clamped = _nodes("clamped_node", clamped_node, beam)
    if len(clamped) != 1:
        raise ValueError("craig_bampton: clamped_node must be a single node (the joint grid J)")
    iface = _nodes("interface_nodes", interface_nodes, beam, clamped)
    sload = _nodes("static_load_nodes", static_load_nodes, beam, clamped + iface)

    M, K = beam.matrices()
    free = free_dofs(beam, clamped, planar)
    i = free_dofs(beam, clamped + iface, planar)  # interior dofs (J and interface held)
    b = np.setdiff1d(free, i)  # interface dofs
    s = np.flatnonzero(np.isin(np.arange(beam.n_dofs) // 6, sload) & np.isin(np.arange(beam.n_dofs), i))
    if len(i) == 0:
        raise ValueError("craig_bampton: no interior dofs left for normal modes")

    # fixed-interface normal modes, Anderson 1993 eq (9) on the interior dofs
    w, X = eigenmodes(M, K, i, dof_groups(i))
    if n_modes is not None:
        if isinstance(n_modes, bool) or int(n_modes) != n_modes or not 0 <= n_modes <= len(i):
            raise ValueError(f"craig_bampton: n_modes must be an integer in 0..{len(i)}, got {n_modes!r}")
        k = int(n_modes)
    else:
        if isinstance(w, jax.core.Tracer):
            raise ValueError("craig_bampton: cutoff needs concrete beam parameters; "
                             "use n_modes under jit/grad")
        if not cutoff > 0:
            raise ValueError(f"craig_bampton: cutoff must be positive, got {cutoff!r}")
        k = int(np.sum(np.asarray(w) <= cutoff))
    kinds = ("normal",) * k + ("constraint",) * len(b) + ("static",) * len(s)
    if not kinds:
        raise ValueError("craig_bampton: empty basis (no normal, constraint or static modes)")
    if len(kinds) == k:
        return ModalBasis(X[:, :k], w[:k], kinds)
    rotate = bool(orthonormalize)
    shapes, freqs = _assemble_basis(beam, w, X, k, tuple(i.tolist()), tuple(b.tolist()), tuple(s.tolist()),
                                    rotate)
    if rotate:
        if not isinstance(freqs, jax.core.Tracer) and not np.all(np.isfinite(np.asarray(freqs))):
            raise ValueError("craig_bampton: the basis columns are linearly dependent")
        kinds = ("reduced",) * len(kinds)
    return ModalBasis(shapes, freqs, kinds)


@eqx.filter_jit
def _assemble_basis(beam, w, X, k, i, b, s, rotate):
    """Columns [normal, constraint, static] and, with `rotate`, the reduced-eigenproblem rotation."""
    M, K = beam.matrices()
    i, b, s = np.array(i, dtype=int), np.array(b, dtype=int), np.array(s, dtype=int)
    cols = [X[:, :k]]  # k static: one compilation per basis layout
    Kii = jax.scipy.linalg.cho_factor(K[np.ix_(i, i)], lower=True)
    if len(b):  # constraint modes: x_i = -K_ii^-1 K_ib for x_b = I
        Psi = jnp.zeros((beam.n_dofs, len(b))).at[b, np.arange(len(b))].set(1.0)
        cols.append(Psi.at[i].set(-jax.scipy.linalg.cho_solve(Kii, K[np.ix_(i, b)])))
    if len(s):  # static-correction modes: x_i = K_ii^-1 e_s
        E = jnp.zeros((len(i), len(s))).at[np.searchsorted(i, s), np.arange(len(s))].set(1.0)
        cols.append(jnp.zeros((beam.n_dofs, len(s))).at[i].set(jax.scipy.linalg.cho_solve(Kii, E)))
    Phi = jnp.concatenate(cols, axis=1)
    if rotate:
        lam, Y = _eigh_generalized(Phi.T @ M @ Phi, Phi.T @ K @ Phi)
        return Phi @ Y, jnp.sqrt(lam)
    return Phi, jnp.concatenate([w[:k], jnp.full((len(b) + len(s),), jnp.nan)])


def reduced(beam: Beam, basis: ModalBasis):
    """Reduced modal mass and stiffness (M_r, K_r) = (phi^T M phi, phi^T K phi), (mu, mu)."""
    M, K = beam.matrices()
    return basis.shapes.T @ M @ basis.shapes, basis.shapes.T @ K @ basis.shapes
