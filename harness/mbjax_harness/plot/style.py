"""Shared look of mbjax figures: one colour and marker per integrator, everywhere; and `Figure`,
whose `savefig` first makes the figure readable (`tidy`): log-axis labels that never collide and
never fewer than two, curves that would hide one another drawn apart. `lint` says what would
still make a figure hard to read (the tests apply it to the tour's figures); `note_in` fills a
panel that has nothing to draw with why."""

import matplotlib.figure
import numpy as np
from matplotlib.ticker import LogFormatterSciNotation, LogLocator, NullFormatter

COLORS = {
    "explicit_euler": "#d62728",
    "semi_implicit_euler": "#ff7f0e",
    "rk4": "#1f77b4",
    "implicit_midpoint": "#2ca02c",
    "rkmk4": "#9467bd",
    "mujoco": "#7f7f7f",
}
MARKERS = {"explicit_euler": "v", "semi_implicit_euler": "^", "rk4": "o",
           "implicit_midpoint": "s", "rkmk4": "D"}


def label(name: str) -> str:
    return name.replace("_", " ")


# --- every figure passes through `tidy` when saved (`Figure.savefig`) ---------------------------

DASHES = ((0, (5, 2)), (0, (1, 1.5)), (0, (6, 2, 1, 2)), (0, (2, 3)))
OVERLAP_MARKERS = ("o", "s", "^", "D")


class Figure(matplotlib.figure.Figure):
    """A matplotlib figure whose `savefig` tidies it first (`tidy`): what every mbjax figure is."""

    def savefig(self, *args, **kwargs):
        tidy(self)
        return super().savefig(*args, **kwargs)


def tidy(fig) -> None:
    """Make every axes of fig readable: tick labels of log axes that never collide, and curves
    that would hide one another drawn apart."""
    restyled = {}
    for ax in fig.axes:
        _log_ticks(ax, "x")
        _log_ticks(ax, "y")
        restyled.update(_separate(ax))
    legends = [ax.get_legend() for ax in fig.axes] + list(fig.legends)
    for legend in filter(None, legends):        # a legend drew its keys before: redraw them
        for text, handle in zip(legend.get_texts(), legend.legend_handles):
            line = restyled.get(text.get_text())
            if line is not None and hasattr(handle, "set_linestyle"):
                handle.set_linestyle(line.get_linestyle())
                handle.set_marker(line.get_marker())
                handle.set_markerfacecolor("none")


def _log_ticks(ax, which: str) -> None:
    """A log axis holding fewer than two powers of ten labels one tick, or (under ~1.5 decades)
    its minor ticks, whose labels run into each other: label 1, 2 and 5 times powers of ten
    instead, and widen the view to two such ticks when it holds fewer."""
    if (ax.get_xscale() if which == "x" else ax.get_yscale()) != "log":
        return
    axis = ax.xaxis if which == "x" else ax.yaxis
    lo, hi = sorted(axis.get_view_interval())
    if lo <= 0 or not np.isfinite(hi) or np.floor(np.log10(hi)) - np.ceil(np.log10(lo)) >= 1:
        return                                       # two powers of ten or more: labelled
    axis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))
    # every major tick labelled (by default only powers of ten are past a decade's span)
    axis.set_major_formatter(LogFormatterSciNotation(minor_thresholds=(np.inf, np.inf)))
    axis.set_minor_formatter(NullFormatter())
    grid = np.array([m * 10.0**e for e in range(int(np.floor(np.log10(lo))) - 1,
                                                 int(np.ceil(np.log10(hi))) + 2) for m in (1, 2, 5)])
    if np.sum((grid >= lo) & (grid <= hi)) < 2:
        below, above = grid[grid <= lo], grid[grid >= hi]
        limits = (below.max() * 0.95 if len(below) else lo, above.min() * 1.05 if len(above) else hi)
        ax.set_xlim(*limits) if which == "x" else ax.set_ylim(*limits)


def _separate(ax) -> dict:
    """A labelled curve drawn in the same style over one that shows the same values (within 1 % of
    the axis at 90 % of the points) gets a dash pattern and sparse hollow markers, offset from the
    first's, so that both stay visible. Returns {label: line} of the curves restyled."""
    lines = [line for line in ax.get_lines() if not line.get_label().startswith("_")
             and len(np.atleast_1d(line.get_xdata())) > 2]
    span = {}
    for which, scale in (("x", ax.get_xscale()), ("y", ax.get_yscale())):
        lo, hi = sorted(ax.get_xlim() if which == "x" else ax.get_ylim())
        span[which] = (np.log10(hi / lo) if scale == "log" and lo > 0 else hi - lo, scale)
    restyled = {}
    for j, line in enumerate(lines):
        for other in lines[:j]:
            if line.get_linestyle() != other.get_linestyle() or not _coincide(line, other, span):
                continue
            k = len(restyled) % len(DASHES)
            n = len(np.atleast_1d(line.get_xdata()))
            every = max(n // 8, 1)
            line.set_linestyle(DASHES[k])
            line.set_marker(OVERLAP_MARKERS[k])
            line.set_markevery((every * (k + 1) // (len(DASHES) + 1), every))
            line.set_markerfacecolor("none")
            line.set_markersize(5)
            restyled[line.get_label()] = line
            break
    return restyled


def _coincide(a, b, span) -> bool:
    """Whether two curves of as many points lie within 1 % of the axes' spans of each other."""
    pairs = [(np.asarray(u, dtype=float), np.asarray(v, dtype=float))
             for u, v in zip(a.get_data(), b.get_data())]
    if any(u.shape != v.shape for u, v in pairs):
        return False
    for (u, v), which in zip(pairs, ("x", "y")):
        size, scale = span[which]
        if scale == "log":
            with np.errstate(divide="ignore", invalid="ignore"):
                u, v = np.log10(np.abs(u)), np.log10(np.abs(v))
        both = np.isfinite(u) & np.isfinite(v)
        close = np.abs(u[both] - v[both]) <= 0.01 * max(size, 1e-300)
        if not both.any() or np.mean(close) < 0.9:
            return False
    return True


# --- what `lint` checks, and `note_in` --------------------------------------------------------

def note_in(ax, text: str) -> None:
    """Write `text` across the middle of an axes that has nothing to draw (a peer not installed:
    "MuJoCo not installed: pip install mujoco") instead of leaving it blank; its ticks go."""
    ax.set_xscale("linear")
    ax.set_yscale("linear")
    ax.set(xticks=[], yticks=[], ylabel="")
    ax.text(0.5, 0.5, text, transform=ax.transAxes, ha="center", va="center", fontsize=8,
            color="0.3", wrap=True)


def _labelled_ticks(ax, which: str) -> int:
    """How many tick labels (major and minor) with text show inside the view of ax's x or y axis;
    ax's figure drawn."""
    axis = ax.xaxis if which == "x" else ax.yaxis
    lo, hi = sorted(axis.get_view_interval())
    count = 0
    for minor in (False, True):
        locs = axis.get_minorticklocs() if minor else axis.get_majorticklocs()
        labels = axis.get_ticklabels(minor=minor)
        count += sum(1 for loc, text in zip(locs, labels, strict=False)
                     if lo * (1 - 1e-9) <= loc <= hi * (1 + 1e-9) and text.get_visible()
                     and text.get_text().strip())
    return count


def _curves(ax) -> list:
    """The lines of ax that are data curves: three or more points, neither coordinate constant
    (not an axhline, an axvline or a marker)."""
    def varies(values) -> bool:
        values = values[np.isfinite(values)]
        return len(values) > 1 and values.min() < values.max()

    curves = []
    for line in ax.get_lines():
        x, y = (np.asarray(v, dtype=float).ravel() for v in line.get_data())
        if len(x) >= 3 and varies(x) and varies(y):
            curves.append(line)
    return curves


def lint(fig) -> list[str]:
    """What makes fig hard to read, one line each (empty: nothing): a log axis showing tick
    labels but fewer than two; an axes with several labelled artists (lines, bars, markers) or
    several data curves (`_curves`) and no legend, on the axes or the figure. Draws the figure."""
    fig.draw_without_rendering()
    problems = []
    for k, ax in enumerate(fig.axes):
        if not ax.get_visible() or not ax.axison:
            continue
        name = f"axes {k} ({ax.get_title() or ax.get_ylabel() or 'untitled'})"
        for which in ("x", "y"):
            if (ax.get_xscale() if which == "x" else ax.get_yscale()) != "log":
                continue
            axis = ax.xaxis if which == "x" else ax.yaxis
            if not any(t.get_visible() for t in axis.get_ticklabels()):
                continue                             # labels hidden on purpose (shared axis)
            n = _labelled_ticks(ax, which)
            if n < 2:
                problems.append(f"{name}: log {which} axis with {n} labelled tick{'s' * (n != 1)}")
        if ax.get_legend() is None and not fig.legends:
            handles, _ = ax.get_legend_handles_labels()
            if len(handles) > 1:
                problems.append(f"{name}: {len(handles)} labelled artists and no legend")
            elif len(_curves(ax)) > 1:
                problems.append(f"{name}: {len(_curves(ax))} curves and no legend")
    return problems
