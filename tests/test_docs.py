"""The documentation site (`mkdocs.yml`, docs/): the API reference generated from the docstrings,
the papers, the conventions and the notebooks with their outputs. It builds in strict mode, so a page naming
an object that no longer exists, or a broken link, fails the suite."""

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).parent.parent


def _build(config: Path, site: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "-f", str(config),
                           "-d", str(site)], capture_output=True, text=True, cwd=config.parent)


def test_the_documentation_builds_strict(tmp_path):
    result = _build(ROOT / "mkdocs.yml", tmp_path / "site")
    assert result.returncode == 0, result.stderr[-4000:]
    flex = (tmp_path / "site" / "api" / "flex" / "index.html").read_text()
    assert "FlexibleSystem" in flex and "craig_bampton" in flex
    assert "simplified" in (tmp_path / "site" / "api" / "integrate" / "index.html").read_text()
    assert "Canfield" in (tmp_path / "site" / "papers" / "index.html").read_text()
    # every notebook is a page, rendered as committed: its figures included
    for notebook in sorted((ROOT / "notebooks").glob("*.ipynb")):
        page = (tmp_path / "site" / "notebooks" / notebook.stem / "index.html").read_text()
        assert "data:image/png;base64" in page, notebook.name


def test_a_reference_to_a_missing_object_fails_the_build(tmp_path):
    docs = tmp_path / "docs"
    docs.mkdir()
    (docs / "index.md").write_text("# broken\n\n::: mbjax.flex.no_such_function\n")
    config = tmp_path / "mkdocs.yml"
    config.write_text((ROOT / "mkdocs.yml").read_text().split("nav:")[0].replace(
        "docs_dir: docs", f"docs_dir: {docs}") + "plugins:\n  - mkdocstrings\n")
    result = _build(config, tmp_path / "site")
    assert result.returncode != 0 and "no_such_function" in result.stderr
