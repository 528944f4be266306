"""Figures of the closed loops (Jerkovsky 1978 §VI, Anderson 1993 §2.4): `mbjax reproduce closed-chain`."""

import numpy as np

from mbjax_harness.plot.style import Figure


def closed_chain_figure(data: dict) -> Figure:
    """(a) CPU time of 1 s of simulation against n, O(n + m^3) against O(n^3) (Anderson 1993 Fig. 8);
    (b) constraint drift |Phi| against time for each stabilization."""
    fig = Figure(figsize=(12, 4.6), layout="constrained")
    ax_t, ax_d = fig.subplots(1, 2)
    ax_t.loglog(data["n"], data["recursive_s"], "o-", label="O(n + m^3): Anderson 1993 recursion")
    ax_t.loglog(data["n"], data["dense_s"], "s--", label="O(n^3): coupled multipliers, dense mass")
    ax_t.set(xlabel="n (tree degrees of freedom)", ylabel="run time for 1 s [s]",
             title="(a) closed chain, Anderson 1993 Fig. 8")
    for name, rows in data["drift"].items():
        rows = np.asarray(rows)
        ax_d.semilogy(rows[1:, 0], np.maximum(rows[1:, 1], 1e-17), label=name)
    ax_d.set(xlabel="t [s]", ylabel="|Phi(q)|", title="(b) constraint drift, 12-dof chain")
    for ax in (ax_t, ax_d):
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=8)
    return fig


def closed_loops_tour_figure(runs: dict, drift: dict, title: str) -> Figure:
    """(a) error after the run against run time, one line per method through its step sizes;
    (b) |Phi| against time at the smallest step."""
    fig = Figure(figsize=(12, 4.6), layout="constrained")
    ax_w, ax_d = fig.subplots(1, 2)
    for name, rows in runs.items():
        seconds = [r["seconds"] for r in rows]
        ax_w.loglog(seconds, [r["error"] for r in rows], "o-", label=name)
        for r, s in zip(rows, seconds):
            ax_w.annotate(f"{r['dt'] * 1e3:g} ms", (s, r["error"]), fontsize=7,
                          textcoords="offset points", xytext=(4, 2))
    ax_w.set(xlabel="run time [s]", ylabel="max joint-angle error [rad]",
             title="(a) speed against accuracy")
    for name, (ts, phi) in drift.items():
        ax_d.semilogy(ts[1:], np.maximum(phi[1:], 1e-17), label=name)
    ax_d.set(xlabel="t [s]", ylabel="|Phi(q)|", title="(b) constraint residual, smallest step")
    for ax in (ax_w, ax_d):
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=8)
    fig.suptitle(title)
    return fig
