"""The README and the guide tell the truth: two set-up commands, CI runs the test one, every command
shown runs as written on the bundled examples, every picture and page it links to exists."""

from __future__ import annotations

import os
import pathlib
import re
import shlex

import pytest
from weft.app.cli import main

ROOT = pathlib.Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text(encoding="utf-8")
GUIDE = sorted((ROOT / "docs").glob("*.rst")) + sorted((ROOT / "docs" / "guide").glob("*.rst"))


def shell_commands(path: pathlib.Path) -> list[str]:
    """The ``weft ...`` lines of a page's shell blocks (README: ```sh fences; docs: ``.. code-block:: sh``),
    in page order. Other lines of those blocks (the set-up commands) are not examples to run here."""
    text = path.read_text(encoding="utf-8")
    if path.suffix == ".md":
        blocks = re.findall(r"```sh\n(.*?)\n```", text, flags=re.S)
    else:
        blocks = re.findall(r"\.\. code-block:: sh\n\n((?:   .*\n|\n)+)", text)
    lines = [line.strip() for block in blocks for line in block.splitlines()]
    return [line for line in lines if line.startswith("weft ")]


def _pages_with_commands() -> list[pathlib.Path]:
    return [p for p in [ROOT / "README.md", *GUIDE] if shell_commands(p)]


def test_exactly_two_setup_commands_and_ci_runs_the_test_one():
    setup = README.split("## Set up", 1)[1].split("\n## ", 1)[0]
    commands = re.findall(r"```sh\n(.*?)\n```", setup, flags=re.S)
    assert len(commands) == 2
    run, test = commands
    assert run == "python3 -m venv .venv && .venv/bin/pip install -e . && .venv/bin/weft"
    assert test == "python3 -m venv .venv && .venv/bin/pip install -e '.[test]' && .venv/bin/python -m pytest"
    assert test in (ROOT / ".ci" / "run").read_text(encoding="utf-8")


def test_the_readme_is_short_and_names_the_docs_build_command():
    assert len(README.splitlines()) <= 300
    assert ".venv/bin/python -m sphinx -W -b html docs docs/_build/html" in README
    assert ".venv/bin/python -m sphinx -W -b html docs docs/_build/html" in (ROOT / ".ci" / "run").read_text()


def test_pictures_and_pages_named_in_the_readme_exist():
    links = re.findall(r"\]\(([^)#]+)\)", README)
    local = [link for link in links if "://" not in link]
    assert any(link.startswith("docs/images/") for link in local)
    for link in local:
        assert (ROOT / link).exists(), link


def test_every_job_of_the_quick_start_has_a_command():
    commands = shell_commands(ROOT / "README.md")
    for job in (
        "weft quilt",
        "weft fast",
        "weft fill resources/coffee.png --mask",
        "weft fill resources/brick.png --extend",
        "weft rectify",
        "weft nfpt",
        "weft batch",
        "weft run",
    ):
        assert any(c.startswith(job) for c in commands), job


@pytest.mark.slow
@pytest.mark.parametrize("page", _pages_with_commands(), ids=lambda p: str(p.relative_to(ROOT)))
def test_every_command_on_the_page_runs_as_written(page, tmp_path, monkeypatch, capsys):
    """Each ``weft`` line runs in a fresh folder holding the repository's ``resources`` and ``docs``
    (the examples' inputs), in page order (a later line may use an earlier one's output), exits 0 and
    writes the file it names."""
    for name in ("resources", "docs"):
        os.symlink(ROOT / name, tmp_path / name)
    monkeypatch.chdir(tmp_path)
    for command in shell_commands(page):
        argv = shlex.split(command.split(" #", 1)[0])[1:]
        code = main(argv)
        err = capsys.readouterr().err
        assert code == 0, f"{page.name}: {command}\n{err}"
        out = argv[argv.index("-o") + 1]
        if "{" in out:  # a batch's pattern: at least one output of that folder
            assert any((tmp_path / out.split("/", 1)[0]).iterdir()), command
        else:
            assert (tmp_path / out).is_file(), command
