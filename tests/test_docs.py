"""The documentation site (`mkdocs.yml`, docs/): the API reference generated from the docstrings,
the papers, the conventions and the notebooks with their outputs. It builds in strict mode, so a page naming
an object that no longer exists, or a broken link or anchor, fails the suite. The site is built once;
the tests read its pages: every public name has an entry, the entry points' parameters are tables,
and the API reference's index reaches them."""

import html
import importlib
import inspect
import os
import re
import subprocess
import sys
from pathlib import Path
from urllib.parse import urljoin, urlparse

import pytest

ROOT = Path(__file__).parent.parent
# the public namespaces, each with its page docs/api/NAME.md; "mbjax" is the top level's
NAMESPACES = ["mbjax"] + sorted(p.stem for p in (ROOT / "mbjax").iterdir()
                                if p.stem != "__init__" and not p.stem.startswith((".", "_"))
                                and (p.suffix == ".py" or (p / "__init__.py").exists()))


def _build(config: Path, site: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "-f", str(config),
                           "-d", str(site)], capture_output=True, text=True, cwd=config.parent,
                          env={**os.environ, "NO_MKDOCS_2_WARNING": "1"})


@pytest.fixture(scope="module")
def site(tmp_path_factory) -> Path:
    """The site, built once (strict) for every test of this module."""
    site = tmp_path_factory.mktemp("docs") / "site"
    result = _build(ROOT / "mkdocs.yml", site)
    assert result.returncode == 0, result.stderr[-4000:]
    return site


def _page(site: Path, namespace: str) -> str:
    return (site / "api" / namespace.removeprefix("mbjax.") / "index.html").read_text()


def _ids(page: str) -> set[str]:
    return {html.unescape(x) for x in re.findall(r'\bid="([^"]+)"', page)}


def _entry(page: str, anchor: str) -> str:
    """The HTML of one object's entry: from its heading to the next object's heading."""
    start = page.index(f'id="{anchor}"')
    end = page.find('class="doc doc-heading"', page.index("</h", start))
    return page[start:end if end > 0 else len(page)]


def _section(entry: str, title: str) -> str:
    """The table of the docstring section `title` ("Parameters", "Returns") in an entry."""
    start = entry.find(f'<span class="doc-section-title">{title}:</span>')
    assert start >= 0, f"no {title} section"
    return entry[start:entry.index("</table>", start)]


def test_the_documentation_builds_strict(site):
    flex = _page(site, "mbjax.flex")
    assert "FlexibleSystem" in flex and "craig_bampton" in flex
    assert "simplified" in _page(site, "mbjax.integrate")
    assert "Canfield" in (site / "papers" / "index.html").read_text()
    # every notebook is a page, rendered as committed: its figures included
    for notebook in sorted((ROOT / "notebooks").glob("*.ipynb")):
        page = (site / "notebooks" / notebook.stem / "index.html").read_text()
        assert "data:image/png;base64" in page, notebook.name


def test_every_public_name_has_an_entry(site):
    """Each namespace's page renders every name of its `__all__` (an anchor at the name's full
    public path), the scenes page every scene module and its builder."""
    assert {"mbjax", "integrate", "trajopt", "scenes", "data"} <= set(NAMESPACES)
    missing = []
    for name in NAMESPACES:
        namespace = "mbjax" if name == "mbjax" else f"mbjax.{name}"
        ids = _ids(_page(site, namespace))
        missing += [f"{namespace}.{x}" for x in importlib.import_module(namespace).__all__
                    if f"{namespace}.{x}" not in ids]
    assert not missing, missing
    scenes = _ids(_page(site, "mbjax.scenes"))
    assert {"mbjax.scenes.rigid_chain.build", "mbjax.scenes.arm.reach_problem",
            "mbjax.scenes.acrobot.swingup_problem"} <= scenes


@pytest.mark.parametrize("namespace, name", [("mbjax.integrate", "simulate"),
                                             ("mbjax.trajopt", "solve"),
                                             ("mbjax.trajopt", "Problem")])
def test_entry_points_render_their_parameters_as_a_table(site, namespace, name):
    """The main entry points' pages list every parameter in a table (with its type), and the
    functions say what they return; a class's table is its constructor's arguments."""
    obj = getattr(importlib.import_module(namespace), name)
    entry = _entry(_page(site, namespace), f"{namespace}.{name}")
    table = _section(entry, "Parameters")
    rows = re.findall(r'<tr class="doc-section-item">\s*<td>\s*<code>(\w+)</code>\s*</td>\s*'
                      r'<td>(.*?)</td>', table, re.S)
    parameters = [p for p in inspect.signature(obj).parameters if p != "self"]
    assert [row[0] for row in rows] == parameters
    untyped = [row[0] for row in rows if not re.sub(r"<[^>]+>", "", row[1]).strip()]
    assert not untyped, f"parameters without a type: {untyped}"
    if inspect.isfunction(obj):
        assert _section(entry, "Returns")
    # a short summary, then the parameters: the longer notes come after the tables
    summary = re.sub(r"<[^>]+>", "", entry[entry.index("doc-contents"):entry.index("Parameters:")])
    assert len(summary.strip()) < 1000, summary


def test_the_api_index_links_resolve(site):
    """Every link of the API reference's index reaches a page of the site, and an anchor on it."""
    index = site / "api" / "index.html"
    page = index.read_text()
    main = page[page.index('<article'):page.index('</article>')]
    links = [html.unescape(x) for x in re.findall(r'<a href="([^"]+)"', main)]
    targets = [x for x in links if not x.startswith("#") and not urlparse(x).scheme]
    assert len(targets) >= 40, targets
    anchored = 0
    for link in targets:
        url = urlparse(urljoin("api/index.html", link))
        path = site / url.path
        path = path / "index.html" if url.path.endswith("/") else path
        assert path.is_file(), link
        if url.fragment:
            anchored += 1
            assert url.fragment in _ids(path.read_text()), link
    assert anchored >= 30
    for entry in ("integrate/#mbjax.integrate.simulate", "trajopt/#mbjax.trajopt.solve",
                  "trajopt/#mbjax.trajopt.Problem", "model/#mbjax.model.load_urdf"):
        assert f'href="{entry}"' in main, entry


@pytest.mark.parametrize("page, error", [
    ("# broken\n\n::: mbjax.flex.no_such_function\n", "no_such_function"),
    # mkdocs.yml's validation: a link to an anchor that does not exist fails a strict build
    ("# broken\n\n[simulate](other.md#mbjax.integrate.no_such_anchor)\n", "no_such_anchor"),
], ids=["missing-object", "missing-anchor"])
def test_a_reference_to_a_missing_object_fails_the_build(tmp_path, page, error):
    docs = tmp_path / "docs"
    docs.mkdir()
    (docs / "index.md").write_text(page)
    (docs / "other.md").write_text("# other\n")
    config = tmp_path / "mkdocs.yml"
    config.write_text((ROOT / "mkdocs.yml").read_text().split("nav:")[0].replace(
        "docs_dir: docs", f"docs_dir: {docs}") + "plugins:\n  - mkdocstrings\n")
    result = _build(config, tmp_path / "site")
    assert result.returncode != 0 and error in result.stderr
