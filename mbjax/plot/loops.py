"""Figures of the closed loops (seeds 001 §VI, 002 §2.4): `mbjax reproduce closed-chain`."""

import numpy as np
from matplotlib.figure import Figure


def closed_chain_figure(data: dict) -> Figure:
    """(a) CPU time of 1 s of simulation against n, O(n + m^3) against O(n^3) (seed 002 Fig. 8);
    (b) constraint drift |Phi| against time for each stabilization."""
    fig = Figure(figsize=(12, 4.6), layout="constrained")
    ax_t, ax_d = fig.subplots(1, 2)
    ax_t.loglog(data["n"], data["recursive_s"], "o-", label="O(n + m^3): seed 002 recursion")
    ax_t.loglog(data["n"], data["dense_s"], "s--", label="O(n^3): coupled multipliers, dense mass")
    ax_t.set(xlabel="n (tree degrees of freedom)", ylabel="run time for 1 s [s]",
             title="(a) closed chain, seed 002 Fig. 8")
    for name, rows in data["drift"].items():
        rows = np.asarray(rows)
        ax_d.semilogy(rows[1:, 0], np.maximum(rows[1:, 1], 1e-17), label=name)
    ax_d.set(xlabel="t [s]", ylabel="|Phi(q)|", title="(b) constraint drift, 12-dof chain")
    for ax in (ax_t, ax_d):
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=8)
    return fig
