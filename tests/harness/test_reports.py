"""Honest reports: the peers each command skipped and why, figures and sentences that say what a
missing peer left out, list lines that are whole sentences, figures that read (`lint`)."""

import io
import subprocess
import sys

import numpy as np
import pytest

from mbjax_harness import peers
from mbjax_harness.cli import _declared, _listing, _report, describe
from mbjax_harness.plot.style import Figure, lint

UNAVAILABLE = {"mujoco": "unavailable: mujoco is not installed",
               "pinocchio": "unavailable: pinocchio is not installed"}


@pytest.fixture
def no_peers(monkeypatch):
    """MuJoCo and Pinocchio hidden, as on a machine without them."""
    monkeypatch.setitem(sys.modules, "mujoco", None)
    monkeypatch.setitem(sys.modules, "pinocchio", None)


def test_a_hidden_peer_is_missing_and_says_what_to_install(no_peers):
    assert not peers.available("mujoco") and not peers.available("mujoco.mjx")
    assert peers.missing("mujoco") == UNAVAILABLE["mujoco"]
    assert peers.note("pinocchio", peers.missing("pinocchio")) == \
        "Pinocchio not installed: pip install pin"
    assert peers.missing("numpy") is None


def test_the_models_scene_records_each_peer_it_could_not_use(no_peers):
    from mbjax_harness.tour import _model_peers

    records = _model_peers()
    assert {name: r["status"] for name, r in records.items()} == UNAVAILABLE
    assert all(r["max_relative_difference"] is None and r["compares"] for r in records.values())


def test_a_peer_that_raises_is_reported_failed_not_the_scene():
    from mbjax_harness.tour import _peer

    def boom():
        raise RuntimeError("no solution")

    value, record = _peer("numpy", "a check", boom)
    assert value is None and record == {"status": "failed: RuntimeError: no solution",
                                        "compares": "a check"}
    assert _peer("numpy", "a check", lambda: 1.5) == (1.5, {"status": "compared",
                                                           "compares": "a check"})


def test_the_closing_line_names_each_skipped_peer_and_the_scenes_that_skipped_it(capsys):
    summary = {"quick": True, "scenes": {
        "controls": {"peers": {"mujoco": {"status": UNAVAILABLE["mujoco"]}}},
        "heavy-top": {"integrators": {"rk4": {"status": "success"}}},
        "models": {"peers": {"pinocchio": {"status": UNAVAILABLE["pinocchio"]},
                             "mujoco": {"status": UNAVAILABLE["mujoco"]}}}}}
    _report([], summary)
    assert capsys.readouterr().out.splitlines()[1] == (
        "peers skipped: mujoco: unavailable: mujoco is not installed (controls, models); "
        "pinocchio: unavailable: pinocchio is not installed (models) "
        '(pip install ".[robots]" installs example-robot-data, Pinocchio, MuJoCo)')
    # a peer compared is not skipped; a record's own "skipped" reason is
    summary["scenes"]["models"]["peers"]["pinocchio"]["status"] = "compared"
    _report([], [summary, {"library": "jaxsim", "skipped": "jaxsim is not installed"}])
    assert capsys.readouterr().out.splitlines()[1] == (
        "peers skipped: jaxsim: skipped: jaxsim is not installed; "
        "mujoco: unavailable: mujoco is not installed (controls, models) "
        '(pip install ".[robots]" installs example-robot-data, Pinocchio, MuJoCo)')
    # a missing peer that the robots extra does not bring names no extra
    _report([], [{"library": "jaxsim", "skipped": "jaxsim is not installed"}])
    assert capsys.readouterr().out.splitlines()[1] == (
        "peers skipped: jaxsim: skipped: jaxsim is not installed")


def test_bench_and_reproduce_name_the_declared_peers_they_left_out(no_peers, capsys):
    from mbjax_harness.bench import SUITES
    from mbjax_harness.reproduce import REPRODUCTIONS

    assert _declared(REPRODUCTIONS["tree-scaling"]) == [
        {"peer": "pinocchio", "status": UNAVAILABLE["pinocchio"]}]
    assert _declared(REPRODUCTIONS["vertical-top"]) == []
    # the records' own word on a peer wins over the declaration's
    _report([], [{"engine": "mujoco", "status": "failed: SolverError"}], _declared(SUITES["rigid"]))
    assert capsys.readouterr().out.splitlines()[1] == (
        "peers skipped: mujoco: failed: SolverError; "
        "pinocchio: unavailable: pinocchio is not installed "
        '(pip install ".[robots]" installs example-robot-data, Pinocchio, MuJoCo)')


def test_what_to_look_at_says_which_comparisons_did_not_run():
    from mbjax_harness.tour import look_at

    both = {"peers": {p: {"status": "compared"} for p in ("pinocchio", "mujoco")}}
    assert "agrees with MuJoCo and Pinocchio" in look_at("models", both)
    one = {"peers": {"pinocchio": {"status": "compared"},
                     "mujoco": {"status": UNAVAILABLE["mujoco"]}}}
    sentence = look_at("models", one)
    assert "agrees with Pinocchio on" in sentence and "MuJoCo not installed: pip install mujoco" \
        in sentence and "with MuJoCo" not in sentence
    none = {"peers": {p: {"status": s} for p, s in UNAVAILABLE.items()}}
    assert "agrees" not in look_at("models", none) and "pip install pin" in look_at("models", none)
    controls = look_at("controls", {"peers": {"mujoco": {"status": UNAVAILABLE["mujoco"]}}})
    assert "not compared with MuJoCo (MuJoCo not installed: pip install mujoco)" in controls
    assert "ends where mujoco.rollout ends" in look_at(
        "controls", {"peers": {"mujoco": {"status": "compared"}}})
    assert look_at("heavy-top", {}).startswith("the energy drift")


def _models_figure(records: dict):
    from mbjax_harness.plot.scenes import models_figure

    ts = np.linspace(0.0, 0.5, 11)
    qs = np.outer(ts, np.arange(1.0, 4.0))
    flange = np.stack([ts, 0 * ts, 1 - ts], axis=1)
    fig = models_figure(ts, qs, -np.ones(3), np.ones(3), flange, records, "test")
    fig.savefig(io.BytesIO(), format="png", dpi=40)
    return fig


def test_the_peer_panel_says_what_to_install_instead_of_staying_blank():
    none = _models_figure({p: {"status": s, "max_relative_difference": None}
                           for p, s in UNAVAILABLE.items()})
    panel = none.axes[2]
    texts = " ".join(t.get_text() for t in panel.texts)
    assert "MuJoCo not installed: pip install mujoco" in texts and "pip install pin" in texts
    assert not panel.patches and lint(none) == []
    one = _models_figure({"pinocchio": {"status": "compared", "max_relative_difference": 3e-14},
                          "mujoco": {"status": UNAVAILABLE["mujoco"],
                                     "max_relative_difference": None}})
    panel = one.axes[2]
    assert len(panel.patches) == 1 and "pip install mujoco" in " ".join(
        t.get_text() for t in panel.texts)
    assert [t.get_text() for t in panel.get_xticklabels()] == ["Pinocchio", "MuJoCo"]
    assert lint(one) == []


def test_lint_finds_a_lone_log_tick_and_a_missing_legend_and_tidy_mends_the_ticks():
    import matplotlib.figure

    from matplotlib.ticker import NullFormatter

    def drawn(cls, labelled: bool, legend: bool = False):
        fig = cls()
        ax_log, ax_lines = fig.subplots(1, 2)
        ax_log.semilogy([0.0, 1.0], [3e-3, 8e-2])           # one power of ten inside the view,
        ax_log.yaxis.set_minor_formatter(NullFormatter())   # and it alone labelled
        for k in range(2):
            ax_lines.plot([0.0, 1.0, 2.0], [k, k + 1.0, k], label=f"line {k}" if labelled else None)
        if legend:
            ax_lines.legend()
        fig.savefig(io.BytesIO(), format="png", dpi=40)
        return fig

    plain = lint(drawn(matplotlib.figure.Figure, labelled=False))
    assert len(plain) == 2 and "log y axis with 1 labelled tick" in plain[0]
    assert "2 curves and no legend" in plain[1]
    assert lint(drawn(Figure, labelled=True)) == ["axes 1 (untitled): 2 labelled artists and no "
                                                  "legend"]
    assert lint(drawn(Figure, labelled=True, legend=True)) == []


def test_a_long_first_sentence_wraps_under_its_name_rather_than_being_cut():
    def long():
        """A first sentence that goes on and on, well past the hundred characters a listing line
        holds, to its very end. A second sentence."""

    assert describe(long).endswith("to its very end.")
    lines = _listing({"name": long}).splitlines()
    assert len(lines) == 2 and lines[1].startswith(" " * 6) and lines[1].endswith("very end.")
    assert describe(long, whole=True).endswith("A second sentence.")


HIDDEN = "import sys; sys.modules['mujoco'] = None; sys.modules['pinocchio'] = None; "


def test_a_tour_without_mujoco_and_pinocchio_says_so(tmp_path):
    """The models scene (the cheapest with peers) in a process where neither imports: the closing
    line names both and the scene, the summary's sentence and peers table say what did not run,
    and the figure passes `lint`."""
    out = subprocess.run(
        [sys.executable, "-c", HIDDEN + "from mbjax_harness.cli import main; sys.exit(main("
         f"['tour', '--quick', '--jobs', '1', '--scene', 'models', '--out', {str(tmp_path)!r}]))"],
        capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.splitlines()[-1] == (
        "peers skipped: mujoco: unavailable: mujoco is not installed (models); "
        "pinocchio: unavailable: pinocchio is not installed (models) "
        '(pip install ".[robots]" installs example-robot-data, Pinocchio, MuJoCo)')
    markdown = (tmp_path / "summary.md").read_text()
    assert "compared with no peer here (Pinocchio not installed: pip install pin; MuJoCo not " \
           "installed: pip install mujoco)" in markdown
    assert "| mujoco | unavailable: mujoco is not installed |" in markdown
