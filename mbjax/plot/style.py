"""Shared look of mbjax figures: one colour and marker per integrator, everywhere."""

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
