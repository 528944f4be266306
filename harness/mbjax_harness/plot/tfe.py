"""Figures of the time finite elements (Borri 1990): `mbjax reproduce vertical-top`,
`torque-free-tfe` and `top-long-run`."""

import numpy as np

from mbjax_harness.plot.style import Figure

NODE_COLORS = {"2": "#1f77b4", "3": "#ff7f0e", "4": "#2ca02c"}
FORM_STYLES = {"primal": "-", "mixed": "--"}


def vertical_top_figure(data: dict) -> Figure:
    """(a) real parts of the exponents against dt, mbjax lines over the paper's tables;
    (b) the same for the imaginary parts; (c) stability boundaries against dt."""
    fig = Figure(figsize=(15, 4.6), layout="constrained")
    ax_re, ax_im, ax_b = fig.subplots(1, 3)
    for key, ls in (("exact", "-"), ("reduced", ":"), ("mixed", "--")):
        for nodes, rows in data[key].items():
            dt = [r["dt"] for r in rows]
            kw = dict(color=NODE_COLORS[nodes], ls=ls, label=f"{key}, {nodes} nodes")
            ax_re.semilogy(dt, np.maximum(np.abs([r["re"] for r in rows]), 1e-12), **kw)
            ax_im.plot(dt, [r["im"] for r in rows], **kw)
    for key, marker in (("exact", "o"), ("reduced", "x")):
        for nodes, rows in data["paper"][key].items():
            kw = dict(color=NODE_COLORS[nodes], marker=marker, ls="none", ms=5)
            ax_re.semilogy([r["dt"] for r in rows], [abs(r["re"]) for r in rows], **kw)
            ax_im.plot([r["dt"] for r in rows], [r["im"] for r in rows], **kw)
    ax_re.axhline(1e-4, color="k", lw=0.6, ls="-.")
    ax_re.set(xlabel="time between nodes dt [s]", ylabel="|Re ln(lambda) / h|",
              title="(a) real part (markers: Tables 1 (o) and 2 (x))", ylim=(1e-12, 1))
    ax_im.axhline(5 / 3, color="k", lw=0.6)
    ax_im.set(xlabel="time between nodes dt [s]", ylabel="Im ln(lambda) / h",
              title="(b) imaginary part (exact: 5/3)")
    b = data["stability_boundary"]
    ax_b.plot(b["dt"], b["exact_closed_form"], color="k", lw=3, alpha=0.3,
              label="eq 7.10: Omega_c sqrt(1 + (omega dt)^2 / 12)")
    ax_b.plot(b["dt"], b["exact"], "o-", ms=3, label="primal, exact integration")
    ax_b.plot(b["dt"], b["reduced"], "x-", ms=4, label="primal, reduced integration")
    ax_b.plot(b["dt"], b["mixed"], "s--", ms=3, mfc="none", label="mixed (eq 4.9)")
    ax_b.axhline(b["physical"], color="k", lw=0.8, ls=":", label="physical Omega_c")
    ax_b.set(xlabel="time between nodes dt [s]", ylabel="least stable spin [rad/s]",
             title="(c) stability boundaries, 2-node elements")
    for ax in (ax_re, ax_im, ax_b):
        ax.grid(True, which="both", alpha=0.3)
    ax_re.legend(fontsize=6, ncol=2)
    ax_b.legend(fontsize=7)
    return fig


def torque_free_figure(data: dict) -> Figure:
    """Borri 1990 Fig. 1 a-e: rotation error against time, primal and mixed, one panel per
    (nodes, spacing)."""
    panels = sorted({(c["nodes"], c["spacing"]) for c in data["cases"]}, key=lambda k: (k[1], k[0]))
    fig = Figure(figsize=(4.2 * len(panels), 4), layout="constrained")
    axes = np.atleast_1d(fig.subplots(1, len(panels), sharey=True))
    for ax, (nodes, spacing), letter in zip(axes, panels, "abcde"):
        for case in data["cases"]:
            if (case["nodes"], case["spacing"]) == (nodes, spacing):
                ax.semilogy(case["t"], np.maximum(case["error"], 1e-12), ls=FORM_STYLES[case["form"]],
                            label=f"{case['form']}: max {case['max_error']:.2g} rad")
        ax.set(title=f"({letter}) {nodes} nodes, {spacing * 1e3:g} ms between nodes",
               xlabel="t [s]")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    axes[0].set_ylabel("rotation error [rad]")
    return fig


RUN_COLORS = {"primal": "#d62728", "primal_reduced": "#9467bd", "mixed": "#2ca02c"}
MARCH_STYLES = {"steady": "-", "constant_velocity": "--"}


def top_long_run_figure(data: dict) -> Figure:
    """(a) tilt against time with the physical one; (b) energy error; (c) error in the vertical
    angular momentum. Solid: about the steady rotation (§6); dashed: reference per element."""
    fig = Figure(figsize=(15, 5.4), layout="constrained")
    ax_tilt, ax_e, ax_h = fig.subplots(1, 3)
    ax_tilt.semilogy(data["physical"]["t"], data["physical"]["tilt"], color="k", lw=2.5, alpha=0.35,
                     label="physical (Dopri8)")
    for r in data["runs"]:
        kw = dict(color=RUN_COLORS[r["form"]], ls=MARCH_STYLES[r["march"]], lw=1.2)
        label = (f"{r['form']}, {r['march']}: growth {r['measured_growth']:+.3f} /s "
                 f"(predicted {r['predicted_growth']:+.3f})")
        ax_tilt.semilogy(r["t"], r["tilt"], label=label, **kw)
        ax_e.semilogy(r["t"][1:], np.maximum(np.abs(r["energy_error"][1:]), 1e-17), **kw)
        ax_h.semilogy(r["t"][1:], np.maximum(np.abs(r["momentum_error"][1:]), 1e-17), **kw)
    fig.suptitle(data["scene"])
    ax_tilt.set(xlabel="t [s]", ylabel="tilt [rad]", title="(a) tilt of the symmetry axis")
    fig.legend(*ax_tilt.get_legend_handles_labels(), loc="outside lower center", ncol=3, fontsize=8)
    ax_e.set(xlabel="t [s]", ylabel="|E / E_0 - 1|", title="(b) energy error")
    ax_h.set(xlabel="t [s]", ylabel="|h_3 - h_3(0)| / |h(0)|",
             title="(c) vertical angular momentum error")
    for ax in (ax_tilt, ax_e, ax_h):
        ax.grid(alpha=0.3, which="both")
    return fig
