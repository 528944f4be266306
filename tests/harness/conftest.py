import pytest


@pytest.fixture(autouse=True)
def _lint_the_tours_figures(monkeypatch):
    """The tour checks each figure it saves here (`mbjax_harness.tour._save`: two labelled ticks on
    every log axis, a legend wherever several lines are drawn) and fails on one that does not
    read; its worker processes inherit the variable."""
    monkeypatch.setenv("MBJAX_LINT_FIGURES", "1")
