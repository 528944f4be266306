"""`mbjax reproduce model-corpus`: every robot model we can find, against its format's engine.
Each model is loaded by mbjax and compared with the engine that owns its format.

URDF: every robot of `example-robot-data`, fixed and floating base, against Pinocchio
(`mbjax_harness.reproduce.urdf_corpus`). MJCF: every model shipped by dm_control, gymnasium and
gymnasium-robotics that MuJoCo compiles, against MuJoCo's `mj_forward` with contacts and
constraints disabled (`mbjax_harness.reproduce.mjcf_corpus`). `--quick`: a few of each.

JSON: {"urdf": [rows], "mjcf": [rows], "mjcf_skipped": [{"model", "reason"}], "tolerance",
"versions"}; a row has "loads", "nv" and "max_relative_difference" (see the two modules for the
quantities compared). Files that are not models on their own (MJCF include fragments, jointless
scenes, an empty URDF) are listed, not counted.
"""

import json
import re
from pathlib import Path

NAME = "model-corpus"
# the peers compared with where installed, left out of the records where not: the
# command's closing line names those missing (`mbjax_harness.cli._declared`)
PEERS = ("pinocchio", "mujoco")
QUICK_URDF = ("panda/panda", "romeo/romeo_small", "go1/go1")


def _versions() -> dict:
    from importlib.metadata import PackageNotFoundError, version
    out = {}
    for package in ("pin", "mujoco", "example-robot-data", "dm_control", "gymnasium",
                    "gymnasium-robotics"):
        try:
            out[package] = version(package)
        except PackageNotFoundError:
            out[package] = None
    return out


def reproduce(out: Path, quick: bool = False) -> dict:
    """Both corpora (quick: a few models of each); writes NAME.json and NAME.png."""
    from mbjax_harness.plot.corpus import corpus_figure
    from mbjax_harness.progress import progress
    from mbjax_harness.reproduce import mjcf_corpus, urdf_corpus

    urdf_paths = urdf_corpus.corpus_paths()
    if quick:
        urdf_paths = [p for p in urdf_paths if urdf_corpus.name(p) in QUICK_URDF]
    mjcf_paths = mjcf_corpus.quick_paths() if quick else mjcf_corpus.corpus_paths()
    urdf = [row for path in progress(urdf_paths, len(urdf_paths), "urdf")
            for row in urdf_corpus.rows([path])]
    surveyed = [mjcf_corpus.survey([path]) for path in progress(mjcf_paths, len(mjcf_paths), "mjcf")]
    data = {"urdf": urdf, "mjcf": [row for rows, _ in surveyed for row in rows],
            "mjcf_skipped": [row for _, skipped in surveyed for row in skipped],
            "tolerance": mjcf_corpus.TOLERANCE, "versions": _versions()}
    out.mkdir(parents=True, exist_ok=True)
    (out / f"{NAME}.json").write_text(json.dumps(data, indent=1))
    corpus_figure(data).savefig(out / f"{NAME}.png", dpi=110)
    return data


_TAGS = (("triangle inequality", "triangle inequality"), ("round-off", "round-off moments"),
         ("not positive semi-definite", "indefinite inertia"), ("massless", "massless leaf"),
         ("rotational inertia but no mass", "inertia without mass"), ("mimic", "mimic joints"))


def _warned(rows) -> str:
    """The kinds of ModelWarning a robot loads with, with how many bodies each names."""
    counts: dict = {}
    for row in rows:
        for message in (row or {}).get("warnings", []):
            for key, tag in _TAGS:
                if key in message:
                    counts[tag] = max(counts.get(tag, 0), sum(key in m for m in row["warnings"]))
    return ", ".join(f"{tag} ({n})" if tag != "mimic joints" else tag for tag, n in counts.items())


def markdown_tables(data: dict) -> str:
    """The two tables of benchmarks/README.md."""
    lines = ["| robot | nv (fixed / floating) | loads | max relative difference (fixed / floating) "
             "| loads with warnings |", "| --- | --- | --- | --- | --- |"]
    by_robot: dict = {}
    for row in data["urdf"]:
        by_robot.setdefault(row["robot"], {})[row["floating"]] = row

    def cell(row, key):
        if not row or not row["loads"]:
            return "n/a"
        return f"{row[key]:.1e}" if key == "max_relative_difference" else str(row[key])

    for robot, pair in by_robot.items():
        rows = [pair.get(False), pair.get(True)]
        if not any(r and r["loads"] for r in rows):
            loads = "not a robot (empty file)" if "no links" in rows[0]["note"] else "no"
        else:
            loads = "yes" + (" (floating only: no joint)" if not rows[0]["loads"] else "")
        lines.append(f"| {robot} | {' / '.join(cell(r, 'nv') for r in rows)} | {loads} | "
                     f"{' / '.join(cell(r, 'max_relative_difference') for r in rows)} | "
                     f"{_warned(rows)} |")
    lines += ["", "| model | nv | loads | max relative difference | not modelled (off in MuJoCo) |",
              "| --- | --- | --- | --- | --- |"]
    for row in data["mjcf"]:
        diff = row["max_relative_difference"]
        ignored = ", ".join(p for p in re.sub(r"\s*\([^)]*\)", "", row["note"]).split("; ") if p)
        lines.append(f"| {row['model']} | {row['nv']} | {'yes' if row['loads'] else 'no'} | "
                     f"{'n/a' if diff is None else f'{diff:.1e}'} | {ignored} |")
    return "\n".join(lines)
