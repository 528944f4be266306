"""The package's layering, checked from the source: no subpackage imports another's private
names, `loops/` holds no type tests on model kinds, and nothing under `scenes/` reaches up to the
command line's `bench/`, `reproduce/`, `tour` or `cli`."""

import ast
from pathlib import Path

PACKAGE = Path(__file__).parent.parent / "mbjax"


def _imports(path: Path):
    """(module, name) for every `from mbjax.x import name` and `import mbjax.x` in a file."""
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("mbjax"):
            yield from ((node.module, alias.name) for alias in node.names)
        elif isinstance(node, ast.Import):
            yield from ((alias.name, None) for alias in node.names if alias.name.startswith("mbjax"))


def _subpackage(module: str) -> str:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else ""


def test_no_subpackage_imports_another_ones_private_names():
    offences = []
    for path in PACKAGE.rglob("*.py"):
        own = path.relative_to(PACKAGE).parts[0].removesuffix(".py")
        for module, name in _imports(path):
            if name and name.startswith("_") and _subpackage(module) != own:
                offences.append(f"{path.relative_to(PACKAGE)}: {module}.{name}")
    assert not offences, offences


def test_scenes_do_not_import_the_command_line_layer():
    upward = {"bench", "reproduce", "tour", "cli"}
    offences = [f"{path.name}: {module}" for path in (PACKAGE / "scenes").glob("*.py")
                for module, _ in _imports(path) if _subpackage(module) in upward]
    assert not offences, offences


def test_loops_tell_no_tree_kinds_apart():
    """The closed loops see any tree through `AbstractTreeSystem`: no isinstance tests on rigid
    or flexible models, no imports of `rigid/` or `flex/`."""
    kinds = {"Model", "FlexibleModel", "TreeSystem", "FlexibleSystem"}
    for path in (PACKAGE / "loops").glob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Call) and getattr(node.func, "id", None) == "isinstance":
                tested = {n.id for n in ast.walk(node.args[1]) if isinstance(n, ast.Name)}
                assert not tested & kinds, (path.name, tested)
        assert not any(_subpackage(m) in {"rigid", "flex"} for m, _ in _imports(path)), path.name
