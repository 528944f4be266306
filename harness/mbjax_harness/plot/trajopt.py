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
    for j in range(us.shape[1]):
        ax_u.step(ts[:-1], us[:, j], where="post", lw=1, label=f"joint {j + 1}")
    ax_u.set(xlabel="t [s]", ylabel="joint torque [N m]", title="controls, held over each step")
    ax_u.legend(fontsize=7, ncol=2)
    for ax in (ax_c, ax_d, ax_u):
        ax.grid(alpha=0.3)
    fig.suptitle(title, fontsize=10)
    return fig


def floating_base_figure(costs, ts, positions, angles, us, bounds, target, title: str) -> Figure:
    """(a) the cost after each iLQR iteration; (b) the base's path in the x-z plane towards its
    target, with its tilt; (c) the four thrusts and their bounds."""
    fig = Figure(figsize=(14, 4.2), layout="constrained")
    ax_c, ax_p, ax_u = fig.subplots(1, 3)
    ax_c.semilogy(np.arange(len(costs)), costs, "o-", ms=3)
    ax_c.set(xlabel="iteration", ylabel="cost", title="iLQR: cost after each iteration")
    ax_p.plot(positions[:, 0], positions[:, 2], "o-", ms=3, label="base")
    ax_p.plot(*target[[0, 2]], "k*", ms=12, label="target")
    for p, a in zip(positions[::3], angles[::3], strict=True):
        ax_p.plot([p[0] - 0.1 * np.cos(a), p[0] + 0.1 * np.cos(a)],
                  [p[2] + 0.1 * np.sin(a), p[2] - 0.1 * np.sin(a)], color="0.4", lw=1)
    ax_p.set(xlabel="x [m]", ylabel="z [m]", title="the base's path (bars: its pitch)",
             aspect="equal")
    ax_p.legend(fontsize=8)
    for i, (u, style) in enumerate(zip(us.T, ("-", "--", "-", ":"), strict=False)):
        ax_u.step(ts[:-1], u, where="post", lw=1.2, ls=style, label=f"rotor {i + 1}")
    for b in bounds:
        ax_u.axhline(b, color="k", ls="--", lw=0.8)
    ax_u.set(xlabel="t [s]", ylabel="thrust [N]", title="thrusts (dashed: their bounds)")
    ax_u.legend(fontsize=8)
    for ax in (ax_c, ax_p, ax_u):
        ax.grid(alpha=0.3)
    fig.suptitle(title, fontsize=10)
    return fig


def gait_figure(histories: dict, ts, forces, mu: float, feet, title: str) -> Figure:
    """(a) the cost after each iteration of each solver (histories: name -> costs); (b) the
    ground's normal force on each foot over the gait; (c) how much of the cost's friction cone
    (its four facets |f_x|, |f_y| <= mu f_n, `friction_cone_residual`) each foot on the ground
    uses, max(|f_x|, |f_y|) / (mu f_n), 1 on the cone (forces (N, F, 3) [N], zero for a foot in
    the air)."""
    fig = Figure(figsize=(14, 4.2), layout="constrained")
    ax_c, ax_n, ax_f = fig.subplots(1, 3)
    for (name, costs), style in zip(histories.items(), ("o-", "s--"), strict=False):
        ax_c.semilogy(np.arange(len(costs)), costs, style, ms=3, label=name)
    ax_c.set(xlabel="iteration", ylabel="cost", title="cost after each iteration")
    ax_c.legend(fontsize=8)
    normal = forces[..., 2]
    tangential = np.abs(forces[..., :2]).max(axis=-1)
    down = normal > 0
    use = np.where(down, tangential / np.where(down, mu * normal, 1.0), np.nan)
    for i, foot in enumerate(feet):
        ax_n.step(ts, normal[:, i], where="post", lw=1.2, label=foot)
        ax_f.plot(ts, use[:, i], ".-", ms=3, lw=1, label=foot)
    ax_n.set(xlabel="t [s]", ylabel="normal force [N]",
             title="the ground's push on each foot (0: in the air)")
    ax_f.axhline(1.0, color="k", ls="--", lw=0.8, label="the cone")
    ax_f.set(xlabel="t [s]", ylabel="max(|f_x|, |f_y|) / (mu f_n)",
             title=f"friction used, the cost's cone at 1 (mu = {mu:g})")
    for ax in (ax_n, ax_f):
        ax.legend(fontsize=8, ncol=2)
    for ax in (ax_c, ax_n, ax_f):
        ax.grid(alpha=0.3)
    fig.suptitle(title, fontsize=10)
    return fig
