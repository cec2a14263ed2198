"""The documentation site (docs/conf.py, ``make docs``) builds strictly: a warning, a broken internal link or a
reference to a missing API name fails it; the gallery's scripts run and make their pictures; the CLI reference
is every subcommand's --help. Each build works on a copy of docs/ (Sphinx and sphinx-gallery write into the
source folder: two builds at once must not share it)."""

from __future__ import annotations

import shutil
import subprocess
import sys

import pytest

from paths import REPO

STRICT = ["-W", "--keep-going", "-n"]


def _copy_docs(tmp_path):
    src = tmp_path / "docs"
    shutil.copytree(REPO / "docs", src, ignore=shutil.ignore_patterns("_build", "auto_examples", "__pycache__"))
    return src


def _sphinx(src, out, *args, timeout=900):
    return subprocess.run([sys.executable, "-m", "sphinx", *STRICT, *args, str(src), str(out)], capture_output=True,
                          text=True, timeout=timeout)


def test_the_readme_is_short_and_links_into_the_site():
    readme = (REPO / "README.md").read_text(encoding="utf-8")
    assert len(readme.splitlines()) <= 200
    for page in ("docs/tutorials/studio.md", "docs/tutorials/your-scan.md", "docs/reference/api.md",
                 "docs/formats.md"):
        assert f"]({page}" in readme and (REPO / page).is_file(), page


@pytest.mark.long("the site's one strict build in the default tier (the gallery is not run: the full tier runs it)")
def test_the_site_builds_strictly(tmp_path):
    src = _copy_docs(tmp_path)
    r = _sphinx(src, tmp_path / "out", "-b", "dummy", "-D", "sphinx_gallery_conf.plot_gallery=0")
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    cli = (src / "reference" / "cli.md").read_text(encoding="utf-8")
    from volanim_core.cli import build_parser, subcommands

    assert all(f"## volanim {name}\n" in cli for name in subcommands(build_parser()))


@pytest.mark.slow
def test_the_site_builds_with_its_gallery_run_and_a_broken_link_fails_it(tmp_path):
    src = _copy_docs(tmp_path)
    out = tmp_path / "html"
    r = _sphinx(src, out, "-b", "html")
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    scripts = sorted((REPO / "docs" / "examples").glob("plot_*.py"))
    assert len(scripts) >= 5
    for script in scripts:  # each ran, and its picture is beside it on its page
        pictures = list((src / "auto_examples" / "images").glob(f"sphx_glr_{script.stem}_*.png"))
        assert pictures, f"{script.name} made no picture"
        page = (out / "auto_examples" / f"{script.stem}.html").read_text(encoding="utf-8")
        assert pictures[0].name in page
    api = (out / "reference" / "api.html").read_text(encoding="utf-8")
    assert 'id="volanim_core.reconstruct.reconstruct"' in api
    # the strictness itself: a link to a section that is not there fails the build, naming the page
    page = src / "tutorials" / "studio.md"
    page.write_text(page.read_text(encoding="utf-8") + "\nSee [nowhere](shape.md#no-such-section).\n",
                    encoding="utf-8")
    broken = _sphinx(src, tmp_path / "broken", "-b", "dummy", "-D", "sphinx_gallery_conf.plot_gallery=0")
    assert broken.returncode != 0 and "studio.md" in broken.stderr and "no-such-section" in broken.stderr
