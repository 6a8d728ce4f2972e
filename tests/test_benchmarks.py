"""The benchmark harness runs a registered case and reports time, memory and quality figures."""

import json

from benchmarks.__main__ import main as bench_main
from benchmarks.cases import CASES, Case, Input
from benchmarks.harness import markdown_table, prepare_inputs, run_case


def test_cases_are_well_formed():
    names = [c.name for c in CASES]
    assert len(names) == len(set(names))
    from core import registry

    for c in CASES:
        method = registry.get(c.method)
        method.params.from_dict({**c.params, **c.quick})  # parameters validate


def test_prepare_inputs_crops_resizes_and_greys():
    case = Case("t", "quilt", {"texture": Input("astronaut", crop=(10, 20, 64, 48), resize=(32, 24), grey=True)}, {})
    tex = prepare_inputs(case)["texture"]
    assert tex.shape == (24, 32)


def test_run_case_row_and_table(monkeypatch):
    monkeypatch.setattr("shutil.which", lambda name: None)  # no G'MIC here: those columns stay out
    case = Case("tiny", "quilt", {"texture": Input("brick", crop=(0, 0, 64, 64))},
                {"block": 16, "size": (64, 64)}, metrics=("coherence", "completeness"))
    row = run_case(case, repeats=2)
    assert row["case"] == "tiny" and row["size"] == [64, 64] and row["runs"] == 2
    assert 0 < row["min_s"] <= row["median_s"]
    assert row["peak_mib"] > 0
    assert 0 <= row["coherence"] < 1 and 0 <= row["completeness"] < 1
    assert "gmic_process_s" not in row
    table = markdown_table([row])
    assert table.splitlines()[0].startswith("| case | output | runs | median s")
    assert "| tiny | 64x64 | 2 |" in table


def test_command_line_writes_json(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr("shutil.which", lambda name: None)
    out = tmp_path / "rows.json"
    assert bench_main(["--quick", "--json", str(out), CASES[0].name]) == 0
    rows = json.loads(out.read_text())
    assert rows[0]["case"] == CASES[0].name
    assert CASES[0].name in capsys.readouterr().out
    assert bench_main(["no-such-case"]) == 2
