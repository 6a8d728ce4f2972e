"""The benchmark harness runs a registered case and reports time, memory and quality figures."""

import json
import sys

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
    case = Case(
        "tiny",
        "quilt",
        {"texture": Input("brick", crop=(0, 0, 64, 64))},
        {"block": 16, "size": (64, 64)},
        metrics=("coherence", "completeness"),
    )
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
    written = json.loads(out.read_text())
    assert written["suite"] == "methods" and written["machine"]["cores"] >= 1 and written["quick"] is True
    assert written["command"].startswith("python -m benchmarks --quick")
    assert written["rows"][0]["case"] == CASES[0].name
    assert CASES[0].name in capsys.readouterr().out
    assert bench_main(["no-such-case"]) == 2


@pytest.mark.slow
def test_cold_runs_a_command_with_stderr_on_a_terminal_and_tables_the_rows(tmp_path):
    import sys

    from benchmarks import cold

    code = "import sys; sys.stderr.write(f'tty {sys.stderr.isatty()}'); sys.stderr.flush(); print('out')"
    r = cold.timed_run([sys.executable, "-c", code], str(tmp_path / "cache"))
    assert r["stderr"] == "tty True"  # the bar and the preparing line are drawn, as in a shell
    assert 0 < r["first_words"] <= r["seconds"] and r["silent"] <= r["seconds"]
    with pytest.raises(RuntimeError, match="exited 3"):
        cold.timed_run([sys.executable, "-c", "raise SystemExit(3)"], str(tmp_path / "cache"))
    row = {
        "command": "fast --target",
        "runs": 3,
        "cold_s": 2.5,
        "warm_s": 0.8,
        "ratio": 3.12,
        "cold_silent_s": 1.3,
        "cold_first_words_s": 0.6,
        "cold_range": [2.4, 2.7],
        "warm_range": [0.8, 0.9],
    }
    table = cold.markdown_table([row])
    assert table.splitlines()[2] == "| fast --target | 2.5 (2.4–2.7) | 0.8 (0.8–0.9) | 3.1x | 0.6 s | 1.3 s |"
    assert set(cold.commands(tmp_path)) >= {
        "studio",
        "quilt --target, 3 passes",
        "nfpt 1024x768",
        "affine",
        "fast --target",
        "warm-up (all methods)",
    }


# --- fill and extend: benchmarks/fill.py and its peer runner --------------------------------------


def _tiny_fill_case():
    import numpy as np

    from benchmarks import fill

    def build():
        from skimage import data

        truth = data.gravel()[:64, :64].copy()
        hole = np.zeros(truth.shape, bool)
        hole[24:40, 20:44] = True
        image = truth.copy()
        image[hole] = 255
        return fill.FillInputs(truth, hole, image, 255)

    return fill.FillCase("fill-tiny", build, "a 64x64 test case")


def test_fill_cases_are_deterministic_with_a_truth_that_agrees_outside_the_hole():
    import numpy as np

    from benchmarks import fill

    names = [c.name for c in fill.CASES]
    assert len(names) == len(set(names)) and all(n.startswith("fill-") for n in names)
    assert not set(names) & {c.name for c in CASES}
    for case in fill.CASES:
        a, b = case.build(), case.build()
        assert np.array_equal(a.image, b.image) and np.array_equal(a.hole, b.hole)
        h, w = a.truth.shape[:2]
        assert 256 <= min(h, w) and max(h, w) <= 384
        assert a.hole.shape == (h, w) and 0 < a.hole.mean() < 0.6
        assert np.array_equal(a.image[~a.hole], a.truth[~a.hole])  # known pixels are the truth's
        assert not np.array_equal(a.image[a.hole], a.truth[a.hole])  # the hole holds no truth
    uncrop = fill.by_name()["fill-uncrop"].build()
    assert uncrop.known_part.shape == (256, 256) and uncrop.truth.shape == (384, 384)
    assert np.array_equal(uncrop.known_part, uncrop.truth[64:320, 64:320])


def test_fill_figures_see_changed_known_pixels_and_the_truth_scores_itself():
    import numpy as np

    from benchmarks import fill

    inputs = _tiny_fill_case().build()
    truth = fill.figures(inputs.truth, inputs)
    assert truth["known_max"] == 0 and truth["band_max"] == 0 and truth["reach_px"] == 0 and truth["unfilled"] == 0
    for name, value in fill.truth_figures(inputs).items():  # the truth's own figures, as the table shows them
        assert truth[name] == value
    out = inputs.truth.copy()
    out[24:40, 17] = out[24:40, 17] // 2 + 10  # 3 px left of the hole: outside the 2-px band
    out[30, 19] = 0  # touching it: inside the band
    figs = fill.figures(out, inputs)
    assert figs["known_max"] == int(np.abs(inputs.truth[24:40, 17].astype(int) - out[24:40, 17]).max())
    assert figs["reach_px"] == 3
    assert figs["band_max"] == int(inputs.truth[30, 19])  # the one change within 2 px of the hole
    painted = fill.figures(inputs.image, inputs)  # nothing filled: the placeholder is still there
    assert painted["unfilled"] == 1.0 and painted["known_max"] == 0


def test_fill_seed_medians_score_each_seed_against_the_truth(monkeypatch):
    """``python -m benchmarks.fill --seeds 0-4``: the median over seeds of each judge, detail as a
    ratio to the truth's and seam as a difference from it; the same seeds give the same figures."""
    from benchmarks import fill

    monkeypatch.setattr(fill, "by_name", lambda: {"fill-tiny": _tiny_fill_case()})
    (row,) = fill.seed_medians(["fill-tiny"], range(3))
    assert row["case"] == "fill-tiny" and len(row["each"]) == 3
    assert row["coherence"] == sorted(row["each"])[1] or abs(row["coherence"] - sorted(row["each"])[1]) < 0.01
    assert 0.5 < row["detail"] < 1.5 and abs(row["seam"]) < 0.5
    assert fill.seed_medians(["fill-tiny"], range(3)) == [row]


def test_fill_peer_runner_fills_the_hole(tmp_path):
    import numpy as np

    from benchmarks import fill_peers

    inputs = _tiny_fill_case().build()
    for peer in ("telea", "shiftmap"):
        out = fill_peers.fill(peer, inputs.image, inputs.hole)
        assert out.shape == inputs.image.shape and out.dtype == np.uint8
        assert (out[inputs.hole] == 255).mean() < 0.2  # the white placeholder is gone
    colour = np.repeat(inputs.image[..., None], 3, axis=2)
    assert fill_peers.fill("telea", colour, inputs.hole).shape == colour.shape
    with pytest.raises(SystemExit, match="unknown peer 'nope'"):
        fill_peers.fill("nope", inputs.image, inputs.hole)


def test_run_fill_case_rows_and_table(monkeypatch):
    from benchmarks import fill

    case = _tiny_fill_case()
    absent = fill.Tool("absent peer", lambda *a: ["true"], lambda: "not installed here")
    rows = fill.run_fill_case(case, repeats=1, quick=True, tools=[*fill.tools_named(["OpenCV Telea"]), absent])
    telea, missing, truth = rows
    assert telea["tool"] == "OpenCV Telea" and telea["runs"] == 1 and telea["size"] == [64, 64]
    assert 0 < telea["process_s"] and 1 < telea["peak_mib"] < 2000
    assert telea["known_max"] == 0 and telea["unfilled"] == 0
    assert telea["detail"] < 0.6 * truth["detail"]  # diffusion smears: the benchmark's reason to be
    assert missing["missing"] == "not installed here" and "process_s" not in missing
    assert truth["tool"] == "ground truth"
    table = fill.markdown_table(rows)
    assert table.splitlines()[0].startswith("fill-tiny (64x64, load average ")
    assert "| absent peer | not run: not installed here |" in table
    assert "| ground truth |" in table


def test_fill_goals_compare_weft_with_the_peers_and_the_truth():
    from benchmarks import fill

    case = fill.by_name()["fill-gravel"]
    peers = [
        {"tool": fill.GMIC, "coherence": 10.0, "process_s": 1.0},
        {"tool": fill.SHIFTMAP, "coherence": 8.0, "process_s": 1.2},
    ]
    truth = {"detail": 1.0, "seam": 1.0}
    good = {"tool": "weft", "coherence": 9.0, "detail": 1.1, "seam": 0.9, "known_max": 0, "process_s": 0.8}
    assert fill.goals(good, peers + [good], truth, case) == "coherence yes, detail yes, seam yes, known yes, time yes"
    bad = {"tool": "weft", "coherence": 9.9, "detail": 0.5, "seam": 1.3, "known_max": 4, "process_s": 1.1}
    assert fill.goals(bad, peers + [bad], truth, case) == "coherence NO, detail NO, seam NO, known NO, time NO"
    uncrop = fill.by_name()["fill-uncrop"]
    assert fill.goals({**good, "process_s": 1.4}, peers, truth, uncrop).endswith("time yes")  # ≤ 1.5 s


@pytest.mark.slow
def test_fill_process_peak_is_the_childs_own():
    import os

    import numpy as np

    from benchmarks import fill

    if not os.path.exists(fill.GNU_TIME):
        pytest.skip("GNU time is not installed: the peak is an upper bound there")
    ballast = np.ones(2**25)  # 256 MiB held by this process while the child runs
    _, rss, err = fill._run(["/bin/true"])
    assert err == "" and 0 < rss < 32 * 2**20 < ballast.nbytes
    _, _, err = fill._run([sys.executable, "-c", "raise SystemExit('boom: a one-line reason')"])
    assert err == "boom: a one-line reason"


def test_command_line_selects_fill_cases_by_pattern(capsys):
    assert bench_main(["--list"]) == 0
    listed = capsys.readouterr().out
    assert "fill-gravel" in listed and "fill-uncrop" in listed and "quilt-mincut-512" in listed
    assert bench_main(["nothing-*"]) == 2
    assert "unknown case nothing-*" in capsys.readouterr().err
    assert bench_main(["fill-gravel", "--tools", "nobody"]) == 2
    assert "no tool matches nobody" in capsys.readouterr().err


@pytest.mark.skipif(
    "fill" not in __import__("weft.core.registry", fromlist=["names"]).names(),
    reason="the fill method is not registered in this checkout",
)
def test_fill_weft_rows_run_the_command_line_on_a_hole_and_an_uncrop():
    import numpy as np

    from benchmarks import fill

    hole_case = _tiny_fill_case()
    rows = fill.run_fill_case(hole_case, repeats=1, quick=True, tools=fill.tools_named(["weft"]))
    weft_rows = [r for r in rows if r["tool"].startswith("weft")]
    assert [r["tool"] for r in weft_rows] == [
        "weft",
        *(f"weft --engine {e}" for e in fill.WEFT_ENGINES),
        "weft --engine patchmatch --structure no",
    ]
    for row in weft_rows:
        assert "error" not in row, row
        assert row["known_max"] == 0 and row["reach_px"] <= fill.BAND and row["unfilled"] < 0.05
        assert row["goals"].startswith("detail") and "known yes" in row["goals"]  # no G'MIC row: no coherence goal

    def build_uncrop():
        inputs = hole_case.build()
        hole = np.ones(inputs.truth.shape, bool)
        hole[16:48, 16:48] = False
        image = inputs.truth.copy()
        image[hole] = 0
        return fill.FillInputs(inputs.truth, hole, image, 0, extend=(16, 16, 16, 16))

    uncrop = fill.FillCase("fill-tiny-uncrop", build_uncrop, "64x64 from its 32x32 centre", uncrop=True)
    row = fill.run_fill_case(uncrop, repeats=1, quick=True, tools=fill.tools_named(["weft"])[:1])[0]
    assert "error" not in row, row
    assert row["known_max"] == 0 and row["unfilled"] < 0.05 and row["size"] == [64, 64]


def test_quilt_samples_tables_old_and_new_defaults(capsys):
    """``python -m benchmarks.quilt_samples``: one row per sample with the resolved default block and
    each figure old -> new; the new figures are the defaults' own."""
    from weft.core.metrics import coherence
    from weft.core.quilting import METHOD, QuiltParams

    from benchmarks import quilt_samples

    assert quilt_samples.main(["--seeds", "1", "--samples", "cat-fur"]) == 0
    row = capsys.readouterr().out.strip().splitlines()[-1]
    cells = [c.strip() for c in row.strip("|").split("|")]
    assert cells[0] == "cat-fur 104x104" and cells[1] == "46"
    tex = quilt_samples.sample("cat-fur")
    new = coherence(METHOD.run({"texture": tex}, QuiltParams(size=(208, 208)), rng=0).image, tex)
    assert cells[2].split(" → ")[1] == f"{new:.4f}"
