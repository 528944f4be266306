"""The figure of `mbjax reproduce trajopt`: cost against time, one panel per problem."""

from matplotlib.figure import Figure

STYLE = {"ilqr": ("#1f77b4", "o"), "lbfgs": ("#ff7f0e", "s"), "adam": ("#7f7f7f", "^")}


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
