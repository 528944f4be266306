"""Figures of trajectory optimisation: cost against time per solver (`mbjax reproduce trajopt`)
and one solved reach (the tour)."""

import numpy as np

from mbjax_harness.plot.style import Figure

STYLE = {"ilqr": ("#1f77b4", "o"), "multiple-shooting": ("#2ca02c", "D"),
         "lbfgs": ("#ff7f0e", "s"), "adam": ("#7f7f7f", "^")}


def trajopt_figure(data: dict) -> Figure:
    names = list(dict.fromkeys(row["name"] for row in data["problems"]))
    fig = Figure(figsize=(6 * len(names), 4.5))
    axes = fig.subplots(1, len(names), squeeze=False)[0]
    for ax, name in zip(axes, names, strict=True):
        for history in (h for h in data["histories"] if h["name"] == name):
            row = next(r for r in data["problems"]
                       if r["name"] == name and r["solver"] == history["solver"])
            color, marker = STYLE.get(history["solver"], ("k", "x"))
            ax.loglog([max(t, 1e-4) for t in history["seconds"]], history["cost"], color=color,
                      marker=marker, markevery=max(len(history["cost"]) // 12, 1), ms=4,
                      label=f"{history['solver']}: {row['iterations']} iterations, "
                            f"{row['seconds']:.2f} s, final error {row['final_error']:.1e} "
                            f"({row['status']})")
        ax.set_xlabel("time [s] (each iteration its share of the solve)")
        ax.set_ylabel("cost")
        ax.set_title(f"{name}: cost against time")
        ax.legend(fontsize=7)
    fig.tight_layout()
    return fig


def reach_figure(costs, ts, flange, target, us, title: str) -> Figure:
    """(a) the cost after each iLQR iteration; (b) the flange's distance to its target along the
    optimised trajectory; (c) the joint torques held over each step."""
    fig = Figure(figsize=(14, 4.2), layout="constrained")
    ax_c, ax_d, ax_u = fig.subplots(1, 3)
    ax_c.semilogy(np.arange(len(costs)), costs, "o-", ms=3)
    ax_c.set(xlabel="iteration", ylabel="cost", title="iLQR: cost after each iteration")
    ax_d.semilogy(ts, np.maximum(np.linalg.norm(flange - target, axis=1), 1e-12))
    ax_d.set(xlabel="t [s]", ylabel="|flange - target| [m]", title="the reach")
    ax_u.step(ts[:-1], us, where="post", lw=1)
    ax_u.set(xlabel="t [s]", ylabel="joint torque [N m]", title="controls, held over each step")
    for ax in (ax_c, ax_d, ax_u):
        ax.grid(alpha=0.3)
    fig.suptitle(title, fontsize=10)
    return fig
