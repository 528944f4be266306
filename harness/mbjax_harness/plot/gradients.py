"""The gradient matrix: relative error of jax.grad and jax.jacfwd against central differences."""

import numpy as np

from mbjax_harness.plot.style import Figure


def gradient_matrix_figure(data: dict) -> Figure:
    """Per cell: the relative errors of grad and jacfwd (log scale) and the time of the check."""
    cells = data["cells"]
    names = [c["name"] for c in cells]
    y = np.arange(len(cells))
    fig = Figure(figsize=(11, 0.32 * len(cells) + 1.6), layout="constrained")
    ax, ax_t = fig.subplots(1, 2, sharey=True, width_ratios=(2, 1))
    floor = 1e-16
    for key, marker, label in (("grad_error", "o", "jax.grad"), ("jacfwd_error", "s", "jax.jacfwd")):
        ax.semilogx(np.maximum([c[key] for c in cells], floor), y, marker, ls="none", label=label,
                    mfc="none" if marker == "s" else None)
    ax.axvline(data["tolerance"], color="k", ls="--", lw=1, label=f"tolerance {data['tolerance']:g}")
    ax.set(yticks=y, yticklabels=names, xlabel="max |derivative - central difference| / max |cd|",
           title=f"against central differences (step {data['step']:g})")
    ax.invert_yaxis()
    ax.grid(alpha=0.3, which="both", axis="x")
    ax.legend(fontsize=8, loc="lower right")
    ax_t.barh(y, [c["seconds"] for c in cells], color="0.6")
    ax_t.set(xlabel="compile + run [s]", title="the check's one call")
    fig.suptitle("jax.grad and jax.jacfwd through simulate")
    ax_t.grid(alpha=0.3, axis="x")
    return fig
