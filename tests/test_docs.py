"""The documentation's sources: pages that say only what is current, promises that name real tests,
tables generated from the specs and from the benchmarks' results files (a missing file is said on the
page). The site itself is built with warnings as errors by ``.ci/run``."""

from __future__ import annotations

import json
import pathlib
import re
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
sys.path.insert(0, str(DOCS / "_ext"))

import weft_docs  # noqa: E402
import weft_results  # noqa: E402

PAGES = [ROOT / "README.md", *sorted(DOCS.rglob("*.rst")), *sorted((DOCS / "gallery").glob("*.py"))]
PAGES = [p for p in PAGES if "_build" not in p.parts and "auto_gallery" not in p.parts]
HISTORY = re.compile(
    r"last round|this round|previous code|previous round|\bissue \d+|\bissues? #\d+|"
    r"\bbefore the .* work\b",
    re.I,
)


def test_the_pages_carry_no_history():
    for page in PAGES:
        for n, line in enumerate(page.read_text(encoding="utf-8").splitlines(), 1):
            assert not HISTORY.search(line), f"{page.relative_to(ROOT)}:{n}: {line.strip()}"


def test_every_promise_names_tests_that_exist():
    text = (DOCS / "promises.rst").read_text(encoding="utf-8")
    items = [i for i in re.split(r"\n- ", text)[1:]]
    assert len(items) >= 10
    for item in items:
        named = re.findall(r"``(tests/[\w/]+\.py)``", item)
        assert named, f"a promise without its test: {item[:80]}"
        for path in named:
            assert (ROOT / path).is_file(), path


def test_every_page_is_in_a_table_of_contents():
    rst = [
        p
        for p in DOCS.rglob("*.rst")
        if "_build" not in p.parts and "auto_gallery" not in p.parts and p.parent.name != "gallery"
    ]
    listed = set()
    for page in rst:
        for block in re.findall(r"\.\. toctree::\n((?:   .*\n|\n)+)", page.read_text(encoding="utf-8")):
            for entry in block.split():
                if not entry.startswith(":"):
                    listed.add((page.parent / entry).resolve())
    for page in rst:
        if page.name != "index.rst" or page.parent != DOCS:
            assert page.with_suffix("").resolve() in listed, page.relative_to(ROOT)


def test_parameter_tables_are_the_specs():
    from weft.core import registry
    from weft.core.params import specs

    for name in registry.methods():
        lines = "\n".join(weft_docs.parameter_lines(name))
        for spec in specs(registry.get(name).params):
            assert f"``{spec.option}``" in lines, (name, spec.option)
            assert spec.help.split()[0] in lines
    assert "--over" in weft_docs.cli_help("batch")


def test_every_parameter_says_what_it_changes():
    from weft.core import registry
    from weft.core.params import specs

    for name in registry.methods():
        for spec in specs(registry.get(name).params):
            assert len(spec.help.split()) >= 4, f"weft {name} {spec.option}: help too short: {spec.help!r}"


def test_a_results_file_renders_as_a_table_with_its_machine_and_command(tmp_path, monkeypatch):
    monkeypatch.setattr(weft_results, "RESULTS", tmp_path)
    (tmp_path / "batch.json").write_text(
        json.dumps(
            {
                "suite": "batch",
                "command": "python -m benchmarks.batch --repeats 1",
                "date": "2030-01-02 03:04 UTC",
                "machine": {"cpu": "Test CPU", "cores": 2},
                "note": "a shared machine",
                "rows": [{"recipe": "fast", "pool": "local, 1 worker", "items_per_s": 12.345, "busy": 0.97}],
            }
        )
    )
    lines = "\n".join(weft_results.render("batch"))
    assert "Test CPU, 2 cores" in lines and "2030-01-02" in lines and "A shared machine" in lines
    assert "``python -m benchmarks.batch --repeats 1``" in lines
    assert "12.35" in lines and "97 %" in lines and "items/s" in lines


def test_a_suite_without_a_description_shows_every_column_and_filters(tmp_path, monkeypatch):
    monkeypatch.setattr(weft_results, "RESULTS", tmp_path)
    (tmp_path / "newsuite.json").write_text(json.dumps([{"case": "a", "seconds": 0.5}, {"case": "b", "seconds": 2.0}]))
    lines = "\n".join(weft_results.render("newsuite:case=b"))
    assert "seconds" in lines and "- b" in lines and "- a" not in lines


def test_a_missing_or_broken_results_file_is_said_on_the_page(tmp_path, monkeypatch):
    monkeypatch.setattr(weft_results, "RESULTS", tmp_path)
    assert "No results file ``benchmarks/results/fill_suite.json`` yet" in "\n".join(weft_results.render("fill_suite"))
    (tmp_path / "cold.json").write_text("{not json")
    assert "No results file" in "\n".join(weft_results.render("cold"))


@pytest.mark.parametrize("suite", sorted(p.stem for p in (ROOT / "benchmarks" / "results").glob("*.json")))
def test_every_committed_results_file_has_its_machine_date_and_command(suite):
    data = json.loads((ROOT / "benchmarks" / "results" / f"{suite}.json").read_text(encoding="utf-8"))
    if isinstance(data, dict) and "rows" in data:
        assert data.get("machine") and data.get("date") and data.get("command"), suite
        assert data["rows"], suite
