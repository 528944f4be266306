"""Topology of a tree of n bodies from its proximal-body array (Anderson 1993 eq 1).

Bodies are numbered 0..n-1 with every body numbered higher than its proximal body (Anderson 1993 §2.1,
rule (i)); the parent of a base body is -1 (Anderson 1993 writes 0 with 1-based labels). From that array
follow the ancestor, distal and descendant sets of Anderson 1993 eqs 2-4, Jerkovsky 1978's path matrix pi
(eq 1) and reference matrix rho (eq 2), with rho pi = I (eq 3), and the depth levels the tree passes
are scheduled on.
"""

from functools import cached_property

import numpy as np

from mbjax._src import runtime


class Topology:
    """The static, hashable topology of a tree of n bodies (Anderson 1993 §2.1; Jerkovsky 1978).

    From the parent array follow the ancestor, distal and descendant sets of Anderson 1993
    eqs 2-4, Jerkovsky 1978's path matrix pi (eq 1) and reference matrix rho (eq 2), and the
    depth levels the tree passes are scheduled on. A `Model` holds one as its `topology`.

    Args:
        parents (Sequence[int]): each body's parent, shape (n,): parents[k] < k (every body numbered
            higher than its parent, Anderson 1993 §2.1 rule (i)), or -1 for a base body.

    Raises:
        ValueError: parents is empty, not integers, out of range, or a body is numbered before
            its parent (which also rules out cycles).
    """

    def __init__(self, parents):
        raw = np.asarray(parents)
        if raw.dtype.kind not in "iub" and not (raw.dtype.kind == "f"
                                                 and np.all(raw == np.round(raw))):
            raise ValueError(f"parents must be body indices (integers, -1 for a base body), got "
                             f"{raw.tolist()}")
        parents = tuple(int(p) for p in raw.astype(np.int64).reshape(-1))
        if not parents:
            raise ValueError("a tree needs at least one body; parents is empty")
        for k, p in enumerate(parents):
            if p < -1 or p >= len(parents):
                raise ValueError(f"parents[{k}] = {p} is out of range: use -1 for a base body or an "
                                 f"index in 0..{len(parents) - 1}")
            if p == k:
                raise ValueError(f"parents[{k}] = {k}: a body cannot be its own parent (a cycle)")
            if p > k:
                raise ValueError(f"parents[{k}] = {p}: every body must be numbered higher than its "
                                 "parent (Anderson 1993 §2.1 rule (i)); renumber the bodies depth-first, "
                                 "which also rules out cycles")
        self.parents = parents

    def __repr__(self) -> str:
        return f"Topology(parents={list(self.parents)})"

    def __eq__(self, other) -> bool:
        return isinstance(other, Topology) and self.parents == other.parents

    def __hash__(self) -> int:
        return hash(self.parents)

    @property
    def n(self) -> int:
        """The number of bodies."""
        return len(self.parents)

    # -- the sets of Anderson 1993 eqs 2-4 ---------------------------------------------------------

    def ancestors(self, k: int) -> tuple[int, ...]:
        """An[k] (eq 2): the bodies between body k and the ground, nearest first, k excluded.

        Args:
            k: a body index.

        Returns:
            The ancestors' indices.
        """
        out, p = [], self.parents[k]
        while p >= 0:
            out.append(p)
            p = self.parents[p]
        return tuple(out)

    def distal(self, k: int) -> tuple[int, ...]:
        """Dist[k] (eq 3): the bodies whose proximal body is k.

        Args:
            k: a body index.

        Returns:
            The children's indices, increasing.
        """
        return tuple(j for j, p in enumerate(self.parents) if p == k)

    def descendants(self, k: int) -> tuple[int, ...]:
        """Des[k] (eq 4): every body outboard of k, k excluded, in increasing order.

        Args:
            k: a body index.

        Returns:
            The descendants' indices.
        """
        return tuple(int(j) for j in np.flatnonzero(self.path_matrix()[:, k]) if j != k)

    # -- Jerkovsky 1978 eqs 1-3 ----------------------------------------------------------------------

    def path_matrix(self) -> np.ndarray:
        """The path matrix pi (Jerkovsky 1978 eq 1).

        pi[i, j] = 1 if body j lies on the path from the ground to body i (j = i included). Row
        i is the inward set i^, column j the outward set j-bar.

        Returns:
            pi, a NumPy int array of shape (n, n).
        """
        pi = np.zeros((self.n, self.n), dtype=np.int64)
        for i, p in enumerate(self.parents):
            if p >= 0:
                pi[i] = pi[p]
            pi[i, i] = 1
        return pi

    def reference_matrix(self) -> np.ndarray:
        """The reference matrix rho (Jerkovsky 1978 eq 2), with rho @ pi = I (eq 3).

        Returns:
            rho, 1 on the diagonal and -1 at (i, parent of i), a NumPy int array of shape
                (n, n).
        """
        rho = np.eye(self.n, dtype=np.int64)
        for i, p in enumerate(self.parents):
            if p >= 0:
                rho[i, p] = -1
        return rho

    # -- levels and pass schedules -------------------------------------------------------------

    @cached_property
    def depth(self) -> tuple[int, ...]:
        """Number of joints between each body and the ground (a base body has depth 0)."""
        depth: list[int] = []
        for p in self.parents:
            depth.append(0 if p < 0 else depth[p] + 1)
        return tuple(depth)

    @cached_property
    def levels(self) -> tuple[tuple[int, ...], ...]:
        """Bodies grouped by depth: levels[d] holds every body of depth d."""
        out: list[list[int]] = [[] for _ in range(max(self.depth) + 1)]
        for k, d in enumerate(self.depth):
            out[d].append(k)
        return tuple(tuple(level) for level in out)

    @cached_property
    def schedule(self) -> tuple[np.ndarray, np.ndarray]:
        """The order a tree pass visits the bodies in: (steps, width) body indices and a mask.

        One body per step in index order (valid because parents come first), or level by level
        (all bodies of one depth at once, vectorized: gathers, a vmapped body, scatters) where
        `levels_pay` and the levels are compact and save steps (at most 3/4 as many steps as
        bodies). Short levels are padded with a repeat of their first body (mask False), so
        padding computes on real data and is dropped.
        """
        width = max(len(level) for level in self.levels)
        if (levels_pay() and len(self.levels) * width <= 2 * self.n
                and 4 * len(self.levels) <= 3 * self.n):
            rows = [list(level) + [level[0]] * (width - len(level)) for level in self.levels]
            mask = [[True] * len(level) + [False] * (width - len(level)) for level in self.levels]
            return np.asarray(rows, dtype=np.int64), np.asarray(mask)
        return (np.arange(self.n, dtype=np.int64).reshape(self.n, 1),
                np.ones((self.n, 1), dtype=bool))


def levels_pay() -> bool:
    """Whether level steps beat one body per step: only where XLA runs each operation of a loop
    body as a kernel of its own.

    Where XLA compiles a loop as one kernel (`mbjax._src.runtime`'s default), a level step's
    scatters keep its loop out of that, so one body per step is faster; with kernels one by one
    (MBJAX_XLA_DEFAULTS=0), levels win on bushy trees. See benchmarks/README.md.

    Returns:
        True where level-by-level schedules pay (XLA's loop hoisting is off).
    """
    return not runtime.HOISTING
