"""The `mbjax` command: the tour of every scene, paper reproductions and benchmark suites.

    mbjax tour [--out DIR] [--quick] [--scene NAME ...] [--jobs N]    |    mbjax tour --list
    mbjax reproduce NAME [--out DIR] [--quick]    |    mbjax reproduce --list
    mbjax bench SUITE [--out DIR] [--quick]       |    mbjax bench --list
    mbjax --version

Every long command shows a running clock on stderr and ends by naming the files it wrote and the
peers it skipped (and why).

Compiled programs are kept on disk between runs (`mbjax.use_compilation_cache`; `mbjax --no-cache ...` or
MBJAX_NO_CACHE=1 turns that off), except by `mbjax bench`, which times the compiles. Outputs are
written whole or not at all (`mbjax_harness.outputs`): an interrupted run leaves the previous
run's files. Unknown names, bad options and an output or cache folder that cannot be written
exit with status 2 and a one-line reason.
"""

import argparse
import inspect
import json
import re
import sys
import textwrap
from functools import partial
from pathlib import Path

from mbjax_harness.outputs import OutputError, staged


def _parser(reproductions, suites, scenes) -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="mbjax", description=__doc__.split("\n\n")[0])
    parser.add_argument("--version", action="version", version=_version())
    parser.add_argument("--no-cache", action="store_true",
                        help="do not keep compiled programs on disk (mbjax.use_compilation_cache)")
    commands = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    tour = commands.add_parser("tour", help="run every scene: figures, animations and a summary "
                               "(about 105 s on 2 cores, 1.3 GB a worker; --quick about 75 s)")
    tour.add_argument("--out", type=Path, default=Path("mbjax-out"), help="output folder")
    tour.add_argument("--quick", action="store_true",
                      help="shorter runs (about 75 s on 2 cores with nothing compiled, 1.0 GB a worker)")
    tour.add_argument("--scene", action="append", choices=list(scenes), metavar="NAME",
                      help=f"run only this scene (repeatable), one of: {', '.join(scenes)}")
    tour.add_argument("--jobs", type=_positive_int, default=None, metavar="N",
                      help="scenes run at once, each in a process of its own (default: one per "
                           "core; 1: one after another in this process, for quiet timings)")
    tour.add_argument("--list", action="store_true", help="list the scenes, one line each")

    rep = commands.add_parser("reproduce", help="reproduce a paper figure or table")
    rep.add_argument("name", nargs="?", choices=sorted(reproductions), metavar="NAME",
                     help=f"one of: {', '.join(sorted(reproductions))}")
    rep.add_argument("--list", action="store_true", help="list the reproductions, one line each")
    rep.add_argument("--out", type=Path, default=Path("mbjax-out"), help="output folder")
    rep.add_argument("--quick", action="store_true", help="fewer sample points")

    bench = commands.add_parser("bench", help="run a benchmark suite")
    bench.add_argument("suite", nargs="?", choices=sorted(suites), metavar="SUITE",
                       help=f"one of: {', '.join(sorted(suites))}")
    bench.add_argument("--list", action="store_true", help="list the suites, one line each")
    bench.add_argument("--out", type=Path, default=Path("mbjax-out/bench"), help="output folder")
    bench.add_argument("--quick", action="store_true", help="fewer configurations")
    return parser


def _version() -> str:
    import platform

    import jax

    import mbjax
    return f"mbjax {mbjax.__version__} (jax {jax.__version__}, Python {platform.python_version()})"


def _owner(obj):
    """What describes `obj`: a suite's `run` or a reproduction's `reproduce` its module."""
    if inspect.isfunction(obj) and obj.__name__ in ("run", "reproduce"):
        return sys.modules.get(obj.__module__)
    return obj


def describe(obj, whole: bool = False) -> str:
    """The first sentence of a module's or function's docstring, whole (never cut), without its
    "`mbjax ...`:" prefix and starting with a capital; whole=True: the whole first paragraph."""
    doc = inspect.getdoc(_owner(obj)) or ""
    text = re.sub(r"^`mbjax [^`]*`:\s*", "", " ".join(doc.split("\n\n")[0].split()))
    text = text[:1].upper() + text[1:]
    return text if whole else re.split(r"(?<=\.)\s(?=[A-Z(])", text)[0]


LISTING_WIDTH = 100


def _listing(entries: dict) -> str:
    """One entry a line: its name and what it does (`describe`); a sentence longer than the line
    goes on under the name's column rather than being cut."""
    width = max(len(name) for name in entries) + 2
    return "\n".join(textwrap.fill(describe(fn), LISTING_WIDTH, initial_indent=f"{name:{width}s}",
                                    subsequent_indent=" " * width, break_on_hyphens=False)
                      for name, fn in sorted(entries.items()))


SKIPPED = ("unavailable", "failed", "skipped")
# the peers the `robots` extra installs (pyproject.toml), as the closing line names them
ROBOT_PEERS = {"example_robot_data": "example-robot-data", "pinocchio": "Pinocchio",
               "mujoco": "MuJoCo"}


def _skipped(records) -> list[str]:
    """The peers a command skipped and why, as "peer: status", followed by the scenes that
    skipped it where there are scenes ("mujoco: unavailable: ... (controls, models)"). Found in
    every record (or JSON object) that names an engine, peer or library other than mbjax and
    whose status says "unavailable", "failed" or "skipped" or that has a "skipped" reason; in
    every scene's "peers" ({peer: {"status": ...}}, `mbjax_harness.tour`); the scenes are the keys
    of a "scenes" object (the tour's summary)."""
    found: dict[tuple[str, str], list[str]] = {}

    def add(engine, status, scene):
        if isinstance(engine, str) and engine != "mbjax" and isinstance(status, str):
            scenes = found.setdefault((engine, status), [])
            if scene is not None and scene not in scenes:
                scenes.append(scene)

    def walk(value, scene=None):
        if isinstance(value, dict):
            engine = value.get("engine", value.get("peer", value.get("library")))
            status, reason = value.get("status"), value.get("skipped")
            if isinstance(status, str) and status.startswith(SKIPPED):
                add(engine, status, scene)
            elif isinstance(reason, str):
                add(engine, reason if reason.startswith(SKIPPED) else f"skipped: {reason}", scene)
            for key, item in value.items():
                if key == "scenes" and isinstance(item, dict):
                    for name, one in item.items():
                        walk(one, name)
                elif key == "peers" and isinstance(item, dict):
                    for peer, record in item.items():
                        if isinstance(record, dict) and str(record.get("status")).startswith(SKIPPED):
                            add(peer, record["status"], scene)
                else:
                    walk(item, scene)
        elif isinstance(value, list):
            for item in value:
                walk(item, scene)

    walk(records)
    return [f"{engine}: {status}" + (f" ({', '.join(scenes)})" if scenes else "")
            for (engine, status), scenes in sorted(found.items())]


def _declared(fn) -> list[dict]:
    """A record {"peer", "status"} for each peer that a suite's or reproduction's module declares
    it compares with (its PEERS) and that is not installed (`mbjax_harness.peers.missing`), for
    the closing line: those modules leave such a peer out of their records."""
    from mbjax_harness import peers

    names = getattr(_owner(fn), "PEERS", ())
    return [{"peer": name, "status": why} for name in names
            if (why := peers.missing(name)) is not None]


def _report(written: list[Path], records, declared=()) -> None:
    """The files a command wrote and the peers it skipped: those its records name (`_skipped`)
    and those `declared` (`_declared`) that its records do not already name."""
    print("wrote " + ", ".join(str(p) for p in written if p.exists()))
    skipped = _skipped(records)
    named = {line.split(":", 1)[0] for line in skipped}
    skipped += _skipped([d for d in declared if d["peer"] not in named])
    robots = [line.split(":", 1)[0] for line in skipped
              if line.split(":", 1)[0] in ROBOT_PEERS and ": unavailable" in line]
    print("peers skipped: " + ("; ".join(skipped) if skipped else "none")
          + (f' (pip install ".[robots]" installs {", ".join(ROBOT_PEERS.values())})'
             if robots else ""))


def _positive_int(text: str) -> int:
    value = int(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be at least 1, got {value}")
    return value


def _tour(out: Path, quick: bool, scenes=None, jobs=None) -> None:
    from mbjax_harness import parallel
    from mbjax_harness.tour import COST, TOUR, run_scene

    names = [name for name in TOUR if not scenes or name in scenes]
    # side by side, the longest first balances the workers; one at a time, the summary's order
    order = names if jobs == 1 else sorted(names, key=lambda name: -COST.get(name, 0.0))
    with staged(out) as staging:
        results = parallel.run(partial(run_scene, out=staging, quick=quick), order, jobs,
                               "mbjax tour")
        summary = {"quick": quick, "scenes": {name: results[name] for name in names}}
        (staging / "summary.json").write_text(json.dumps(summary, indent=1))
        (staging / "summary.md").write_text(_summary_markdown(summary))
    files = [f for s in summary["scenes"].values() for f in (s["figure"], s.get("animation")) if f]
    _report([out / "summary.json", out / "summary.md", *(out / f for f in files)], summary)


# headers in words, units in brackets (`_header`); other keys: underscores to spaces, a unit suffix
# (_m, _rad, _s, _in, _seconds) to a bracket
HEADERS = {
    "seconds": "run time [s]", "compile_seconds": "compile time [s]", "dt": "step [s]",
    "duration": "duration [s]", "status": "status", "error_estimate": "error estimate",
    "invariant_drift": "invariant drift (relative)", "energy_drift": "energy drift (relative)",
    "energy_error": "energy error (relative)", "peak_relative_error": "peak error (relative)",
    "against_reference": "against the reference", "relative_difference": "relative difference",
    "seconds_per_step": "time per step [s]", "grad_seconds": "gradient time [s]",
    "grad_compile_seconds": "gradient compile time [s]", "n_bending": "bending modes",
    "max_abs_diff_mujoco_rad": "max difference from MuJoCo [rad]",
}
UNITS = {"m": "m", "rad": "rad", "s": "s", "in": "in", "seconds": "s", "mm": "mm"}

STATUS_NOTE = ("*status* is the run's own verdict: success, or inaccurate where its error estimate "
               "or invariant drift exceeds the scene's tolerance (rtol 1e-3, atol 1e-4), or what "
               "went wrong (non-finite, not converged, constraint violated). Whether a model "
               "follows a reference is a column of its own. Run times are single runs on a shared "
               "machine: differences under about 20 % are noise.")


def _header(key: str) -> str:
    if key in HEADERS:
        return HEADERS[key]
    words = key.split("_")
    if len(words) > 1 and words[-1] in UNITS:
        return " ".join(words[:-1]) + f" [{UNITS[words[-1]]}]"
    return " ".join(words)


def _cell(value) -> str:
    if isinstance(value, bool) or value is None:
        return "—" if value is None else ("yes" if value else "no")
    if isinstance(value, float):
        return f"{value:.3g}"
    if isinstance(value, (list, tuple)):
        return ", ".join(_cell(v) for v in value)
    return str(value)


def _tables(scene: dict) -> tuple[list[str], list[str]]:
    """(tables, facts): every dict of dicts as a table of its own (one experiment each), every
    scalar as a fact."""
    tables, facts = [], []
    for key, value in scene.items():
        if key in ("figure", "animation", "wall_seconds", "look_at"):
            continue
        if isinstance(value, dict) and value and all(isinstance(v, dict) for v in value.values()):
            columns = list(dict.fromkeys(k for row in value.values() for k in row
                                         if not isinstance(row[k], dict)))
            tables += [f"**{_header(key)}**", "",
                       "| | " + " | ".join(_header(c) for c in columns) + " |",
                       "|---" * (len(columns) + 1) + "|"]
            tables += [f"| {name} | " + " | ".join(_cell(row.get(c)) for c in columns) + " |"
                       for name, row in value.items()]
            tables.append("")
        elif isinstance(value, dict):
            facts += [f"{_header(key)}, {_header(k)}: {_cell(v)}" for k, v in value.items()
                      if not isinstance(v, dict)]
        else:
            facts.append(f"{_header(key)}: {_cell(value)}")
    return tables, facts


def _summary_markdown(summary: dict) -> str:
    """`summary.md` for people: per scene, what it shows and what to look at (the scene's own
    description, its "look_at", `mbjax_harness.tour.look_at`), its figure, one table per
    experiment with headers in words and units (the peers it compared with, or why not, among
    them), its settings and results, and its wall time."""
    from mbjax_harness.tour import TOUR, look_at

    lines = ["# mbjax tour" + (" (quick)" if summary["quick"] else ""), "", STATUS_NOTE, ""]
    for name, scene in summary["scenes"].items():
        lines += [f"## {name}", "", describe(TOUR[name], whole=True) if name in TOUR else "", ""]
        sentence = scene.get("look_at") or look_at(name, scene)
        if sentence:
            lines += [f"*What to look at:* {sentence}", ""]
        lines += [f"![{name}]({scene['figure']})", ""]
        if "animation" in scene:
            lines += [f"![{name}, the motion]({scene['animation']})", ""]
        tables, facts = _tables(scene)
        lines += tables
        if facts:
            lines += [f"- {fact}" for fact in facts] + [""]
        lines += [f"wall time {scene['wall_seconds']:.1f} s (compiling, running and drawing)", ""]
    return "\n".join(lines)


def _one_device_per_core() -> None:
    """The throughput, trajopt and mpc suites split batches over one XLA CPU device per core, as the
    peers' batches run one thread per core. Host devices are fixed when JAX starts its backend, so this only takes effect
    before that (as here, from the command line) and where XLA_FLAGS does not set them already."""
    import os

    from jax._src import xla_bridge

    flags = os.environ.get("XLA_FLAGS", "")
    if "host_platform_device_count" not in flags and not xla_bridge.backends_are_initialized():
        os.environ["XLA_FLAGS"] = f"{flags} --xla_force_host_platform_device_count={os.cpu_count() or 1}"


def main(argv=None) -> int:
    import jax

    jax.config.update("jax_enable_x64", True)
    from mbjax_harness.bench import SUITES
    from mbjax_harness.reproduce import REPRODUCTIONS

    from mbjax_harness.tour import TOUR

    parser = _parser(REPRODUCTIONS, SUITES, TOUR)
    args = parser.parse_args(argv)
    try:
        return _run(parser, args, REPRODUCTIONS, SUITES, TOUR)
    except OutputError as error:
        print(f"mbjax: error: --out: {error}", file=sys.stderr)
        return 2


def _run(parser, args, reproductions: dict, suites: dict, scenes: dict) -> int:
    """The parsed command `args`; its exit status."""
    from mbjax import use_compilation_cache

    if not args.no_cache and args.command != "bench":   # benchmarks time the compiles themselves
        try:
            use_compilation_cache()
        except OSError as error:
            print(f"mbjax: error: the compilation cache's folder ({error.filename}) cannot be "
                  f"written: {error.strerror or error}; set JAX_COMPILATION_CACHE_DIR or run "
                  "mbjax --no-cache", file=sys.stderr)
            return 2
    if args.command == "bench" and args.suite in ("throughput", "trajopt", "mpc"):
        _one_device_per_core()
    from mbjax_harness.progress import progress

    if args.command == "tour":
        if args.list:
            print(_listing(scenes))
            return 0
        _tour(args.out, args.quick, args.scene, args.jobs)
    elif args.command == "reproduce":
        if args.list:
            print(_listing(reproductions))
            return 0
        if args.name is None:
            parser.error(f"reproduce needs a NAME, one of: {', '.join(sorted(reproductions))}")
        with staged(args.out) as staging:
            for name in progress([args.name], 1, "mbjax reproduce"):     # a running clock
                data = reproductions[name](staging, quick=args.quick)
        _report([args.out / f"{args.name}.json", args.out / f"{args.name}.png"], data,
                _declared(reproductions[args.name]))
    elif args.command == "bench":
        if args.list:
            print(_listing(suites))
            return 0
        if args.suite is None:
            parser.error(f"bench needs a SUITE, one of: {', '.join(sorted(suites))}")
        with staged(args.out) as staging:
            for name in progress([args.suite], 1, "mbjax bench"):
                records = suites[name](staging, quick=args.quick)
        _report([args.out / f"{args.suite}.jsonl", args.out / f"{args.suite}.png"], records,
                _declared(suites[args.suite]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
