"""The benchmark harness runs a registered case and reports time, memory and quality figures."""

import json

import pytest

from benchmarks.__main__ import main as bench_main
from benchmarks.cases import CASES, Case, Input
from benchmarks.harness import markdown_table, prepare_inputs, run_case


def test_cases_are_well_formed():
    names = [c.name for c in CASES]
    assert len(names) == len(set(names))
    from weft.core import registry

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


def test_cold_runs_a_command_with_stderr_on_a_terminal_and_tables_the_rows(tmp_path):
    import sys

    from benchmarks import cold

    code = "import sys; sys.stderr.write(f'tty {sys.stderr.isatty()}'); sys.stderr.flush(); print('out')"
    r = cold.timed_run([sys.executable, "-c", code], str(tmp_path / "cache"))
    assert r["stderr"] == "tty True"  # the bar and the preparing line are drawn, as in a shell
    assert 0 < r["first_words"] <= r["seconds"] and r["silent"] <= r["seconds"]
    with pytest.raises(RuntimeError, match="exited 3"):
        cold.timed_run([sys.executable, "-c", "raise SystemExit(3)"], str(tmp_path / "cache"))
    row = {"command": "fast --target", "runs": 3, "cold_s": 2.5, "warm_s": 0.8, "ratio": 3.12, "cold_silent_s": 1.3,
           "cold_first_words_s": 0.6, "cold_range": [2.4, 2.7], "warm_range": [0.8, 0.9]}
    table = cold.markdown_table([row])
    assert table.splitlines()[2] == "| fast --target | 2.5 (2.4–2.7) | 0.8 (0.8–0.9) | 3.1x | 0.6 s | 1.3 s |"
    assert set(cold.commands(tmp_path)) >= {"studio", "quilt --target, 3 passes", "nfpt 1024x768", "affine",
                                              "fast --target", "warm-up (all methods)"}
