"""The package's structure, checked from the source so that it cannot drift: the layers read in one
direction, the implementation is private behind a curated public API, and `import mbjax` loads no
harness (command line, tour, benchmarks, reproductions, plotting)."""

import ast
import importlib
import re
import subprocess
import sys
from pathlib import Path

import mbjax

ROOT = Path(__file__).parent.parent
PACKAGE = ROOT / "mbjax"
SRC = PACKAGE / "_src"
HARNESS = ROOT / "harness" / "mbjax_harness"

# mbjax/_src's packages and modules, lowest first: each may import its own layer and those below
# (and `mbjax.data`, the model files shipped with the package)
LAYERS = (
    {"runtime", "linalg", "linear_map", "cache"},
    {"lie", "spatial", "tree"},
    {"model"},                        # with the closures' data types
    {"control"},
    {"system"},                       # AbstractSystem, AbstractTreeSystem, driven systems, Status
    {"rigid", "wrist"},
    {"flex"},                         # flexible bodies reuse the rigid kinematics
    {"loops", "tfe"},
    {"integrate"},
    {"contact"},                      # contacts with the ground: closures of a legged robot,
                                      # simulated through a schedule
    {"trajopt"},
    {"synthesis", "scenes", "gaits"},  # the Carpal Wrist's synthesis; the ready-made scenes;
                                       # legged robots' gait problems
)
RANK = {name: rank for rank, names in enumerate(LAYERS) for name in names}
NAMESPACES = ("lie", "model", "control", "integrate", "rigid", "flex", "loops", "tfe", "wrist",
              "trajopt", "scenes", "data", "contact", "gaits")
MAX_PUBLIC_NAMES = 218       # 150, the contact namespace (legged robots), multi-phase problems,
                             # contacts that find themselves (geoms, their system and model,
                             # the Ant's and HalfCheetah's files) and contact costs (issue 45),
                             # model-predictive control (MPC, Plan, Cycle, Tick,
                             # ClosedLoop, closed_loop, follow), the private door closed (issue
                             # 60): integrate.INTEGRATORS, scenes.TOLERANCE, flex.centreline,
                             # flex.geometric_stiffness, rigid.frame_poses; strategy objects for
                             # string options (issue 60): trajopt.cosine_adam, wrist.AbstractGradient,
                             # wrist.ForwardMode, wrist.ReverseMode, tfe.AbstractQuadrature,
                             # tfe.ExactQuadrature, tfe.ReducedQuadrature, tfe.AbstractReference,
                             # tfe.ConstantReference, tfe.ConstantVelocityReference,
                             # model.AbstractSiblingOrder, model.ByName, model.InDocument,
                             # the cut-joint kinds loops.AbstractCutKind, loops.Spherical,
                             # loops.Revolute, loops.Universal, loops.Weld, loops.SpatialWeld,
                             # loops.Prismatic, loops.PointOnLine, loops.PointOnPlane;
                             # gait builders (issue 61): gaits.Gait, Weights, QUADRUPED, BIPED,
                             # walk, trot, jump


def _imports(path: Path):
    """Every mbjax module a file imports (`from mbjax.x import y` also as mbjax.x.y)."""
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and node.module and node.module.split(".")[0] in (
                "mbjax", "mbjax_harness"):
            yield node.module
            yield from (f"{node.module}.{alias.name}" for alias in node.names)
        elif isinstance(node, ast.Import):
            yield from (a.name for a in node.names if a.name.split(".")[0] in ("mbjax", "mbjax_harness"))


def _layer(module: str) -> str | None:
    parts = module.split(".")
    return parts[2] if parts[:2] == ["mbjax", "_src"] and len(parts) > 2 else None


def test_layers_read_in_one_direction():
    assert set(RANK) == {p.stem for p in SRC.iterdir() if p.stem != "__init__" and
                         (p.suffix == ".py" or p.is_dir()) and p.name != "__pycache__"}
    offences = []
    for path in SRC.rglob("*.py"):
        own = path.relative_to(SRC).parts[0].removesuffix(".py")
        if own == "__init__":
            continue
        for module in _imports(path):
            if module.split(".")[0] == "mbjax_harness" or (module.startswith("mbjax") and not
                                                           module.startswith(("mbjax._src", "mbjax.data"))):
                offences.append(f"{path.relative_to(ROOT)} imports {module} (above the library)")
                continue
            layer = _layer(module)
            if layer in RANK and RANK[layer] > RANK[own]:
                offences.append(f"{path.relative_to(ROOT)} ({own}) imports {module} ({layer})")
    assert not offences, "\n".join(sorted(set(offences)))


def test_no_two_library_modules_import_each_other():
    """The private modules' imports (at module level and inside functions alike) form no cycle:
    `Model.locked` and `lock_joints` imported each other, the one circle there was."""
    modules = {}
    for path in SRC.rglob("*.py"):
        parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
        name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        modules[name] = path
    graph = {name: {m for m in _imports(path) if m in modules and m != name
                    and not name.startswith(m + ".")}           # a module's own package
             for name, path in modules.items() if not path.name == "__init__.py"}
    graph = {name: {m for m in targets if m in graph} for name, targets in graph.items()}
    cycles, state = [], {}

    def visit(name, trail):
        state[name] = "open"
        for m in sorted(graph[name]):
            if state.get(m) == "open":
                cycles.append(" -> ".join(trail[trail.index(m):] + [m]))
            elif m not in state:
                visit(m, trail + [m])
        state[name] = "done"

    for name in sorted(graph):
        if name not in state:
            visit(name, [name])
    assert not cycles, "\n".join(cycles)


def test_the_library_never_imports_the_harness():
    offences = [f"{path.relative_to(ROOT)}: {module}" for path in PACKAGE.rglob("*.py")
                for module in _imports(path) if module.startswith("mbjax_harness")]
    assert not offences, offences


def test_the_benchmarks_and_the_reproductions_do_not_import_each_other():
    """`mbjax_harness.bench` and `mbjax_harness.reproduce` share their helpers through neutral
    modules (`mbjax_harness.common`, `mbjax_harness.timing`), at module level and inside
    functions alike: the tree-scaling reproduction took its workloads from the rigid benchmark,
    the speed and accuracy benchmarks theirs from two reproductions (issue 60)."""
    offences = [f"{path.relative_to(ROOT)}: {module}"
                for package, other in (("reproduce", "bench"), ("bench", "reproduce"))
                for path in sorted((HARNESS / package).rglob("*.py"))
                for module in _imports(path)
                if module == f"mbjax_harness.{other}" or module.startswith(f"mbjax_harness.{other}.")]
    assert not offences, "\n".join(offences)


def test_the_tour_is_a_package_of_short_modules():
    """`mbjax_harness.tour` is the scene registry and one module per family of scenes, each
    under 400 lines (issue 60: one 980-line file held them all)."""
    tour = HARNESS / "tour"
    assert (tour / "__init__.py").is_file() and not (HARNESS / "tour.py").exists()
    lengths = {path.name: len(path.read_text().splitlines()) for path in sorted(tour.rglob("*.py"))}
    assert len(lengths) > 2, lengths
    assert all(n < 400 for n in lengths.values()), lengths


def test_no_type_tests_on_concrete_systems_outside_their_package():
    """trajopt, integrate and loops see systems through `AbstractSystem` and `AbstractTreeSystem`:
    no isinstance on a concrete system outside the package that defines it (checking that an
    argument is the data type a constructor takes, a `Model`, is not such a test)."""
    concrete = {"TreeSystem": "rigid", "MomentumSystem": "rigid", "BatchTreeSystem": "rigid",
                "RigidBody": "rigid", "FlexibleSystem": "flex", "ClosedSystem": "loops",
                "WristSystem": "wrist"}
    offences = []
    for path in SRC.rglob("*.py"):
        own = path.relative_to(SRC).parts[0]
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Call) and getattr(node.func, "id", None) == "isinstance":
                tested = {n.id for n in ast.walk(node.args[1]) if isinstance(n, ast.Name)}
                offences += [f"{path.relative_to(ROOT)}: isinstance(..., {name})"
                             for name in tested if name in concrete and concrete[name] != own
                             and own not in ("scenes", "synthesis")]
    assert not offences, offences


def test_most_modules_are_private():
    modules = [p for p in PACKAGE.rglob("*.py")]
    private = [p for p in modules if "_src" in p.relative_to(PACKAGE).parts]
    assert len(private) >= 0.8 * len(modules), (len(private), len(modules))


def test_the_public_api_is_curated():
    """At most MAX_PUBLIC_NAMES names in `mbjax` and its namespaces, each defined, each namespace
    reachable after `import mbjax`, re-exporting from the private implementation only."""
    count = len(mbjax.__all__)
    for name in NAMESPACES:
        namespace = getattr(mbjax, name)
        assert all(hasattr(namespace, x) for x in namespace.__all__), name
        count += len(namespace.__all__)
    assert all(hasattr(mbjax, x) for x in mbjax.__all__)
    assert count <= MAX_PUBLIC_NAMES, count
    for path in PACKAGE.glob("*.py"):
        for module in _imports(path):
            assert module.startswith(("mbjax._src", "mbjax.")) or module == "mbjax", (path, module)


def test_public_names_have_google_style_docstrings():
    """Every public function and class has a docstring with an `Args:` section where it takes
    arguments and a `Returns:` section where it is a function (Google style, which the
    documentation site renders); enums and warnings excepted."""
    import enum
    import inspect

    items = [(f"mbjax.{x}", getattr(mbjax, x)) for x in mbjax.__all__]
    for name in NAMESPACES:
        namespace = importlib.import_module(f"mbjax.{name}")
        items += [(f"mbjax.{name}.{x}", getattr(namespace, x)) for x in namespace.__all__]
    missing = []
    for name, obj in items:
        if (inspect.ismodule(obj) or not callable(obj)
                or (inspect.isclass(obj) and issubclass(obj, enum.Enum | Warning))):
            continue
        doc = inspect.getdoc(obj) or ""
        params = [p for p in inspect.signature(obj).parameters if p not in ("self", "args", "kwargs")]
        if params and "Args:" not in doc:
            missing.append(f"{name}: no Args section")
        if inspect.isfunction(obj) and "Returns:" not in doc:
            missing.append(f"{name}: no Returns section")
    assert not missing, "\n".join(missing)


def test_import_mbjax_loads_no_harness_or_plotting():
    code = ("import sys, mbjax; print(' '.join(sorted(m for m in sys.modules if m in "
            "('matplotlib', 'diffrax') or m.startswith(('matplotlib.', 'diffrax.', "
            "'mbjax_harness')))))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                         cwd=ROOT)
    assert out.stdout.strip() == "", out.stdout


def test_the_library_alone_requires_neither_plotting_nor_diffrax():
    """The library's distribution (the repository root) needs jax, equinox, optax and numpy; the
    harness (harness/, the `mbjax` command) is a distribution of its own that brings matplotlib
    and diffrax, and `solve_reference`'s diffrax is the `reference` extra."""
    import tomllib

    library = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    names = [re.split(r"[<>=;\[ ]", r)[0] for r in library["dependencies"]]
    assert names == ["jax", "jaxlib", "equinox", "optax", "numpy"], names
    assert "scripts" not in library
    assert library["optional-dependencies"]["reference"] == ["diffrax>=0.6"]
    harness = tomllib.loads((HARNESS.parent / "pyproject.toml").read_text())["project"]
    assert harness["scripts"] == {"mbjax": "mbjax_harness.cli:main"}
    assert {re.split(r"[<>=]", r)[0] for r in harness["dependencies"]} >= {
        "mbjax", "matplotlib", "diffrax"}


PRIVATE = "mbjax._src"


def test_nothing_outside_the_library_and_tests_names_the_private_package():
    """The harness, the benchmarks, the notebooks, the documentation and the README reach mbjax
    through its public API only, and their prose names public objects (or, for an
    implementation detail, its file: mbjax/_src/x.py, a location, not an import)."""
    import json

    texts = [(path, path.read_text()) for path in sorted(HARNESS.rglob("*.py"))]
    texts += [(path, path.read_text()) for path in sorted((ROOT / "benchmarks").rglob("*"))
              if path.suffix in (".py", ".md")]
    texts += [(path, path.read_text()) for path in sorted((ROOT / "docs").rglob("*.md"))]
    texts.append((ROOT / "README.md", (ROOT / "README.md").read_text()))
    offences = []
    for path, text in texts:
        offences += [f"{path.relative_to(ROOT)}:{n}: {line.strip()}"
                     for n, line in enumerate(text.splitlines(), 1) if PRIVATE in line]
    for path in sorted((ROOT / "notebooks").glob("*.ipynb")):
        for k, cell in enumerate(json.loads(path.read_text())["cells"]):
            source = "".join(cell["source"])
            offences += [f"{path.relative_to(ROOT)}: cell {k}, line {n}: {line.strip()}"
                         for n, line in enumerate(source.splitlines(), 1) if PRIVATE in line]
    assert not offences, "\n".join(offences)


def _public_items():
    """(public name, object) for `mbjax`'s and each namespace's `__all__`, and for each class
    its public methods and properties."""
    import inspect

    items = [(f"mbjax.{x}", getattr(mbjax, x)) for x in mbjax.__all__]
    for name in NAMESPACES:
        namespace = importlib.import_module(f"mbjax.{name}")
        items += [(f"mbjax.{name}.{x}", getattr(namespace, x)) for x in namespace.__all__]
    for name, obj in list(items):
        if inspect.isclass(obj):
            items += [(f"{name}.{attr}", member) for attr, member in vars(obj).items()
                      if not attr.startswith("_") and (callable(member) or isinstance(
                          member, property | staticmethod | classmethod))]
    return items


def _raised_strings(tree: ast.AST):
    """(line, text) of every string constant and f-string part in what a `raise` raises and in
    the arguments of `eqx.error_if`, `eqx.branched_error_if`, `warnings.warn` and
    `raise_on_failure` (whose `who` an error names)."""
    calls = ("error_if", "branched_error_if", "warn", "raise_on_failure")
    for node in ast.walk(tree):
        if isinstance(node, ast.Raise) and node.exc is not None:
            parts = [node.exc]
        elif isinstance(node, ast.Call) and (getattr(node.func, "attr", None) in calls
                                             or getattr(node.func, "id", None) in calls):
            parts = [*node.args, *(k.value for k in node.keywords)]
        else:
            continue
        for part in parts:
            for leaf in ast.walk(part):
                if isinstance(leaf, ast.Constant) and isinstance(leaf.value, str):
                    yield leaf.lineno, leaf.value


def test_no_public_docstring_or_error_message_names_the_private_package():
    """What a user reads, a public object's docstring (`help`, the API reference) and an error
    or warning the library raises, names public objects, never the private package."""
    import inspect

    offences = [f"{name}: its docstring names {PRIVATE}" for name, obj in _public_items()
                if PRIVATE in (inspect.getdoc(obj.fget if isinstance(obj, property) else obj)
                               or "")]
    for path in sorted(SRC.rglob("*.py")):
        offences += [f"{path.relative_to(ROOT)}:{line}: {text!r}"
                     for line, text in _raised_strings(ast.parse(path.read_text()))
                     if PRIVATE in text]
    assert not offences, "\n".join(offences)


def test_public_docstrings_fit_a_screen():
    """A public object's docstring says what it does in a screen: at most 40 lines besides its
    Args list (`Model`'s thirty arguments alone take 59); the long sections (formulation,
    methods, sources) live on the documentation site's Details page."""
    import inspect

    def length(doc: str) -> int:
        lines, inside = doc.splitlines(), False
        count = 0
        for line in lines:
            if line == "Args:":
                inside = True
                continue
            if inside and line and not line.startswith(" "):
                inside = False
            count += not inside
        return count

    offences = [f"{name}: {length(doc)} lines" for name, obj in _public_items()
                if length(doc := inspect.getdoc(obj.fget if isinstance(obj, property) else obj)
                          or "") > 40]
    assert not offences, offences


def test_scenes_do_not_import_the_harness():
    offences = [f"{path.name}: {module}" for path in (SRC / "scenes").glob("*.py")
                for module in _imports(path) if module.startswith("mbjax_harness")]
    assert not offences, offences
