"""`weft batch`: one recipe over many frames, on local processes (Dask: tests/test_batch_dask.py).

Every output must be byte for byte `weft run` on that item's recipe; a bad frame fails only itself;
a re-run resumes; nothing is ever overwritten that is an input, nor left half-written when killed.
"""

from __future__ import annotations

import contextlib
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from weft.app.cli import main
from weft.core import batch
from weft.core.errors import WeftError
from weft.core.image import load_image, read_recipe, save_image
from weft.core.limits import LimitError

ROOT = Path(__file__).resolve().parents[1]
WEFT = [sys.executable, "-c", "import sys; from weft.app.cli import main; sys.exit(main())"]


def make_frames(folder: Path, n: int, size=(40, 48)) -> list[Path]:
    """``n`` frames: shifted crops of a bundled photo (like frames of a pan)."""
    photo = load_image(ROOT / "resources" / "astronaut.png").image
    folder.mkdir(parents=True, exist_ok=True)
    h, w = size
    paths = []
    for i in range(n):
        p = folder / f"frame_{i + 1}.png"  # 1..n: natural order puts frame_10 after frame_9
        save_image(p, photo[3 * i : 3 * i + h, 5 * i : 5 * i + w])
        paths.append(p)
    return paths


@pytest.fixture
def scene(tmp_path):
    """A fast-transfer recipe (gravel onto a frame, seed 7) and five frames."""
    frames = make_frames(tmp_path / "frames", 5)
    gravel = load_image(ROOT / "resources" / "gravel.png").image[:64, :64]
    save_image(tmp_path / "gravel.png", gravel)
    recipe = {
        "weft": 1,
        "method": "fast",
        "params": {"n": 5},
        "inputs": {"texture": "gravel.png", "target": "frames/frame_1.png"},
        "seed": 7,
    }
    (tmp_path / "look.json").write_text(json.dumps(recipe))
    return tmp_path, frames


def run(argv, capsys):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.mark.slow
def test_each_output_is_weft_run_on_its_recipe_byte_for_byte(scene, capsys):
    tmp, frames = scene
    code, out, err = run(
        [
            "batch",
            tmp / "look.json",
            "--over",
            "target",
            tmp / "frames",
            "-o",
            tmp / "out" / "{stem}_{index:02d}.png",
            "--workers",
            "2",
            "--report",
        ],
        capsys,
    )
    assert code == 0, err
    assert err.strip() == "5 written"
    lines = [json.loads(line) for line in out.splitlines()]
    assert lines[-1]["summary"] is True and lines[-1]["written"] == 5 and lines[-1]["failed"] == 0
    items = sorted(lines[:-1], key=lambda d: d["index"])
    assert [d["input"] for d in items] == [f"frame_{i}.png" for i in range(1, 6)]
    assert all(d["status"] == "written" and d["seconds"] >= 0 for d in items)
    for i, _frame in enumerate(frames):
        made = tmp / "out" / f"frame_{i + 1}_{i:02d}.png"
        recipe = json.loads(read_recipe(made))
        assert recipe["inputs"] == {"texture": "../gravel.png", "target": f"../frames/frame_{i + 1}.png"}
        assert recipe["seed"] == 7  # the recipe's seed on every frame by default
        # The item's recipe as a user would write it, run with `weft run` into a sibling folder (so
        # the relative paths in its recipe chunk are the same): the very same bytes.
        item = {
            "weft": 1,
            "method": "fast",
            "params": recipe["params"],
            "inputs": {"texture": "gravel.png", "target": f"frames/frame_{i + 1}.png"},
            "seed": 7,
        }
        (tmp / f"item{i}.json").write_text(json.dumps(item))
        ref = tmp / "ref" / made.name
        ref.parent.mkdir(exist_ok=True)
        assert run(["run", tmp / f"item{i}.json", "-o", ref], capsys)[0] == 0
        assert ref.read_bytes() == made.read_bytes()


@pytest.mark.slow
def test_an_exported_png_is_a_recipe_and_seed_per_item_varies_the_seed(scene, capsys):
    tmp, frames = scene
    assert run(["run", tmp / "look.json", "-o", tmp / "look.png"], capsys)[0] == 0
    code, _, err = run(
        [
            "batch",
            tmp / "look.png",
            "--over",
            "target",
            str(tmp / "frames" / "frame_*.png"),
            "-o",
            tmp / "out" / "{index}.png",
            "--seed-per-item",
            "--seed",
            "100",
            "--workers",
            "1",
        ],
        capsys,
    )
    assert code == 0, err
    seeds = [json.loads(read_recipe(tmp / "out" / f"{i}.png"))["seed"] for i in range(5)]
    assert seeds == [100, 101, 102, 103, 104]
    a, b = (load_image(tmp / "out" / f"{i}.png").image for i in (0, 1))
    assert a.shape == b.shape == (40, 48, 3)


@pytest.mark.slow
def test_a_corrupt_frame_fails_alone_with_its_reason(scene, capsys):
    tmp, frames = scene
    data = frames[2].read_bytes()
    frames[2].write_bytes(data[: len(data) // 2])  # truncated mid-stream
    (tmp / "frames" / "frame_9.png").write_bytes(b"")  # and an empty one
    code, out, err = run(
        [
            "batch",
            tmp / "look.json",
            "--over",
            "target",
            tmp / "frames",
            "-o",
            tmp / "out" / "{stem}.png",
            "--report",
            "--workers",
            "1",
        ],
        capsys,
    )
    assert code == 1
    last = err.strip().splitlines()[-1]
    assert last.startswith("4 written, 2 failed: frame_3.png: truncated or corrupt PNG data"), last
    assert "; frame_9.png: empty file" in last
    assert sorted(p.name for p in (tmp / "out").iterdir()) == [
        "frame_1.png",
        "frame_2.png",
        "frame_4.png",
        "frame_5.png",
    ]
    failed = [json.loads(line) for line in out.splitlines() if '"failed"' in line and "summary" not in line]
    assert {d["input"] for d in failed} == {"frame_3.png", "frame_9.png"}
    assert all(d["error"].startswith(str(tmp / "frames")) for d in failed)


@pytest.mark.slow
def test_rerun_skips_what_is_done_and_force_redoes_it(scene, capsys):
    tmp, frames = scene
    argv = [
        "batch",
        tmp / "look.json",
        "--over",
        "target",
        tmp / "frames",
        "-o",
        tmp / "out" / "{stem}.png",
        "--report",
        "--workers",
        "1",
    ]
    assert run(argv, capsys)[0] == 0
    before = {p.name: p.read_bytes() for p in (tmp / "out").iterdir()}
    (tmp / "out" / "frame_2.png").unlink()  # an interrupted batch: two outputs never written
    (tmp / "out" / "frame_5.png").unlink()
    code, out, err = run(argv, capsys)
    assert code == 0 and err.strip() == "2 written, 3 already done"
    status = {json.loads(line).get("input"): json.loads(line).get("status") for line in out.splitlines()[:-1]}
    assert status == {
        "frame_1.png": "skipped",
        "frame_2.png": "written",
        "frame_3.png": "skipped",
        "frame_4.png": "skipped",
        "frame_5.png": "written",
    }
    assert {p.name: p.read_bytes() for p in (tmp / "out").iterdir()} == before
    # Another seed is another recipe: nothing is skipped. --force redoes items with the same recipe.
    code, _, err = run([*argv, "--seed", "8"], capsys)
    assert code == 0 and err.strip() == "5 written"
    code, _, err = run([*argv, "--seed", "8", "--force"], capsys)
    assert code == 0 and err.strip() == "5 written"


@pytest.mark.slow
def test_a_recipe_without_seed_keeps_the_seed_of_its_first_run_when_resumed(scene, capsys):
    tmp, frames = scene
    data = json.loads((tmp / "look.json").read_text())
    data["seed"] = None
    (tmp / "look.json").write_text(json.dumps(data))
    argv = [
        "batch",
        tmp / "look.json",
        "--over",
        "target",
        tmp / "frames",
        "-o",
        tmp / "out" / "{stem}.png",
        "--workers",
        "1",
    ]
    assert run(argv, capsys)[0] == 0
    seed = json.loads(read_recipe(tmp / "out" / "frame_1.png"))["seed"]
    (tmp / "out" / "frame_1.png").unlink()
    code, _, err = run(argv, capsys)
    assert code == 0 and err.strip() == "1 written, 4 already done"
    assert json.loads(read_recipe(tmp / "out" / "frame_1.png"))["seed"] == seed


@pytest.mark.parametrize(
    "pattern, fragment",
    [
        ("frames/{stem}.png", "refusing to overwrite the input file"),
        ("out/all.png", "gives {out}/all.png for both frame_1.png and frame_2.png"),
        ("out/{stme}.png", "uses {stme}; it may use {stem}, {name}, {index}, {target}"),
        ("out/{index:q}.png", "Unknown format code 'q'"),
        ("out/{stem}.gif", "cannot save this format"),
    ],
)
def test_a_bad_pattern_is_refused_before_any_work(scene, capsys, pattern, fragment):
    tmp, frames = scene
    before = {p: p.read_bytes() for p in frames}
    code, out, err = run(["batch", tmp / "look.json", "--over", "target", tmp / "frames", "-o", tmp / pattern], capsys)
    assert code == 2 and out == ""
    assert len(err.strip().splitlines()) == 1
    assert fragment.replace("{out}", str(tmp / "out")) in err, err
    assert not (tmp / "out").exists()
    assert {p: p.read_bytes() for p in frames} == before


@pytest.mark.parametrize(
    "args, fragment",
    [
        (["--over", "photo", "frames"], "--over photo: fast has no input 'photo' (it takes texture, target, mask)"),
        (["--over", "target", "nowhere"], "--over target nowhere: no such file or folder"),
        (["--over", "target", "frames/*.jpg"], "matches no files"),
        (
            ["--over", "target", "frames", "--over", "mask", "frames/frame_1.png"],
            "the --over lists differ in length (target: 5 files, mask: 1 files)",
        ),
        (["--over", "target", "frames", "--workers", "0"], "parameter 'workers' = 0 is outside 1..1024"),
    ],
)
def test_bad_lists_and_options_exit_2(scene, capsys, monkeypatch, args, fragment):
    tmp, _ = scene
    monkeypatch.chdir(tmp)
    code, out, err = run(["batch", "look.json", *args, "-o", "out/{stem}.png"], capsys)
    assert code == 2 and out == "" and not (tmp / "out").exists()
    assert fragment in err, err


def test_a_bad_recipe_exits_2(scene, capsys):
    tmp, _ = scene
    (tmp / "bad.json").write_text(
        json.dumps({"weft": 1, "method": "fast", "params": {"n": 4}, "inputs": {"texture": "gravel.png"}, "seed": 1})
    )
    code, _, err = run(
        ["batch", tmp / "bad.json", "--over", "target", tmp / "frames", "-o", tmp / "out/{stem}.png"], capsys
    )
    assert code == 2 and "bad.json: parameter 'n'" in err and not (tmp / "out").exists()


def test_memory_for_all_workers_is_checked_up_front(scene, capsys, monkeypatch):
    tmp, _ = scene
    # Each item (a 48x40 fast transfer) is estimated at 50 B per output pixel = 96000 B.
    monkeypatch.setattr("weft.core.batch.memory.available_memory", lambda: 150_000)
    code, _, err = run(
        [
            "batch",
            tmp / "look.json",
            "--over",
            "target",
            tmp / "frames",
            "-o",
            tmp / "out/{stem}.png",
            "--workers",
            "2",
        ],
        capsys,
    )
    assert code == 2 and not (tmp / "out").exists()
    assert err.strip() == (
        "weft: batch: one item (frame_1.png) needs about 0 MiB of memory, 2 workers at once "
        "0 MiB, 0 MiB is available: use --workers 1"
    )
    monkeypatch.setattr("weft.core.batch.memory.available_memory", lambda: 50_000)
    code, _, err = run(
        [
            "batch",
            tmp / "look.json",
            "--over",
            "target",
            tmp / "frames",
            "-o",
            tmp / "out/{stem}.png",
            "--workers",
            "1",
        ],
        capsys,
    )
    # every item too large even alone: each fails by itself (exit 1), nothing is run or written
    assert code == 1 and not (tmp / "out").exists()
    assert err.strip().splitlines()[-1].startswith("0 written, 5 failed: frame_1.png: needs about 0 MiB of memory")


@pytest.mark.slow
def test_shipped_inputs_and_outputs_give_the_same_files(scene, capsys):
    tmp, frames = scene
    base = ["batch", tmp / "look.json", "--over", "target", tmp / "frames"]
    assert run([*base, "-o", tmp / "a/{stem}.png", "--workers", "1"], capsys)[0] == 0
    code, _, err = run([*base, "-o", tmp / "b/{stem}.png", "--ship-inputs", "--ship-outputs", "--workers", "1"], capsys)
    assert code == 0, err
    for f in frames:
        # The same pixels; the recipe chunks differ only by the output folder's name (a/ vs b/ are
        # siblings, so not at all).
        assert (tmp / "a" / f.name).read_bytes() == (tmp / "b" / f.name).read_bytes()


@pytest.mark.slow
def test_shipped_inputs_name_the_original_file_when_bad(scene, capsys):
    tmp, frames = scene
    frames[1].write_bytes(b"not an image at all")
    code, out, err = run(
        [
            "batch",
            tmp / "look.json",
            "--over",
            "target",
            tmp / "frames",
            "-o",
            tmp / "b/{stem}.png",
            "--ship-inputs",
            "--workers",
            "1",
        ],
        capsys,
    )
    assert code == 1
    assert (
        err.strip().splitlines()[-1] == "4 written, 1 failed: frame_2.png: not an image file (cannot identify format)"
    )


def test_plan_lists_in_natural_order_and_zips_several_inputs(scene):
    tmp, frames = scene
    make_frames(tmp / "more", 12)
    masks = tmp / "masks"
    masks.mkdir()
    for i in range(12):
        save_image(masks / f"m{i:02d}.png", np.ones((64, 64), np.float32))
    p = batch.plan(
        str(tmp / "look.json"),
        [("target", str(tmp / "more")), ("mask", str(masks))],
        str(tmp / "o" / "{target}-{mask}.png"),
    )
    assert [Path(i.output).name for i in p.items][:3] == ["frame_1-m00.png", "frame_2-m01.png", "frame_3-m02.png"]
    assert Path(p.items[9].inputs["target"]).name == "frame_10.png"
    assert p.skipped == () and len(p.todo) == 12 and p.seed == 7


@pytest.mark.slow
def test_cancel_stops_the_batch_between_items(scene):
    tmp, frames = scene
    from weft.core.jobs import CancelToken

    p = batch.plan(str(tmp / "look.json"), [("target", str(tmp / "frames"))], str(tmp / "o" / "{stem}.png"))
    token = CancelToken()
    seen = []

    def on_outcome(o):
        seen.append(o)
        token.cancel()  # after the first item

    summary = batch.run(p, workers=1, on_outcome=on_outcome, cancel=token)
    assert summary.cancelled and 1 <= summary.written < 5
    assert summary.line().endswith("not done (cancelled)")
    assert sorted(os.listdir(tmp / "o")) == sorted(Path(o.output).name for o in seen if o.status == "written")


def _wait_for(predicate, timeout=60.0):
    deadline = time.monotonic() + timeout
    while not predicate():
        assert time.monotonic() < deadline, "timed out"
        time.sleep(0.01)


@pytest.fixture
def slow_scene(tmp_path):
    """Quilting transfers of ~0.1-0.3 s each: slow enough to kill a batch between its items."""
    frames = make_frames(tmp_path / "frames", 8, size=(96, 96))
    gravel = load_image(ROOT / "resources" / "gravel.png").image[:96, :96]
    save_image(tmp_path / "gravel.png", gravel)
    recipe = {
        "weft": 1,
        "method": "quilt",
        "params": {"block": 12, "overlap": 4},
        "inputs": {"texture": "gravel.png"},
        "seed": 3,
    }
    (tmp_path / "look.json").write_text(json.dumps(recipe))
    return tmp_path, frames


@pytest.mark.slow
def test_a_killed_batch_leaves_whole_outputs_and_resumes(slow_scene):
    tmp, frames = slow_scene
    argv = [
        "batch",
        str(tmp / "look.json"),
        "--over",
        "target",
        str(tmp / "frames"),
        "-o",
        str(tmp / "out" / "{stem}.png"),
        "--workers",
        "1",
    ]
    proc = subprocess.Popen(
        [*WEFT, *argv, "--report"],
        cwd=tmp,
        start_new_session=True,
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        text=True,
    )

    def gone(pid):
        try:
            with open(f"/proc/{pid}/stat") as f:
                return f.read().rsplit(")", 1)[1].split()[0] == "Z"  # a zombie has ended
        except FileNotFoundError:
            return True

    try:  # kill the client (not its worker) as soon as two outputs exist
        worker = int(json.loads(proc.stdout.readline())["worker"].rsplit(":", 1)[1])
        _wait_for(lambda: len(list((tmp / "out").glob("*.png"))) >= 2)
        proc.kill()
        proc.wait()
        assert proc.returncode == -signal.SIGKILL
        _wait_for(lambda: gone(worker))  # the orphaned worker ends by itself, within a second
    finally:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(proc.pid, signal.SIGKILL)  # nothing of the group may outlive a failed test
        proc.stdout.close()
    written = sorted((tmp / "out").glob("*.png"))
    assert 2 <= len(written) < 8, "the kill must land mid-batch"
    # Every PNG there is whole and complete (atomic writes: a temp file never has the output's name).
    for p in written:
        assert load_image(p).image.shape[:2] == (96, 96)
        assert json.loads(read_recipe(p))["seed"] == 3
    kept = {p.name: p.read_bytes() for p in written}
    done = subprocess.run([*WEFT, *argv, "--report"], cwd=tmp, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    lines = [json.loads(line) for line in done.stdout.splitlines()]
    assert lines[-1]["written"] == 8 - len(written) and lines[-1]["skipped"] == len(written)
    assert {p.name: p.read_bytes() for p in written} == kept  # not redone
    assert sorted(p.name for p in (tmp / "out").glob("*.png")) == sorted(f.name for f in frames)
    # ...and the result is what one uninterrupted run gives.
    again = subprocess.run(
        [*WEFT, *argv[:-4], "-o", str(tmp / "ref" / "{stem}.png")], cwd=tmp, capture_output=True, text=True
    )
    assert again.returncode == 0, again.stderr
    for f in frames:
        assert np.array_equal(load_image(tmp / "out" / f.name).image, load_image(tmp / "ref" / f.name).image)


@pytest.mark.slow
def test_a_local_worker_killed_mid_batch_is_replaced_and_no_item_is_lost(slow_scene):
    tmp, frames = slow_scene
    p = batch.plan(str(tmp / "look.json"), [("target", str(tmp / "frames"))], str(tmp / "o" / "{stem}.png"))
    pool = batch.LocalPool(2, "quilt")
    killed = []

    def on_outcome(o):
        if not killed:  # after the first item: kill the other worker, busy with its own item
            pids = [pid for pid in pool.executor._processes if f":{pid}" != o.worker[o.worker.rindex(":") :]]
            os.kill(pids[0], signal.SIGKILL)
            killed.append(pids[0])

    try:
        summary = batch.run(p, pool=pool, on_outcome=on_outcome)
    finally:
        pool.close()
    assert killed and pool.restarts == 1
    assert summary.written == 8 and not summary.failed, summary.line()
    assert sorted(os.listdir(tmp / "o")) == sorted(f.name for f in frames)
    for f in frames:
        assert load_image(tmp / "o" / f.name).image.shape[:2] == (96, 96)


def test_plan_messages_without_over(scene):
    tmp, _ = scene
    with pytest.raises(WeftError, match="no --over INPUT FILES given"):
        batch.plan(str(tmp / "look.json"), [], str(tmp / "o/{stem}.png"))


def test_check_memory_names_the_largest_item(scene):
    tmp, frames = scene
    save_image(tmp / "frames" / "frame_6.png", np.zeros((200, 100, 3), np.float32))
    p = batch.plan(str(tmp / "look.json"), [("target", str(tmp / "frames"))], str(tmp / "o/{stem}.png"))
    need, label = batch.item_memory(p.items)
    assert (need, label) == (50 * 200 * 100, "frame_6.png")
    with pytest.raises(LimitError, match=r"use --workers 3$"):
        batch.check_memory(p.items, 4, available=3 * 50 * 200 * 100)
    batch.check_memory(p.items, 3, available=3 * 50 * 200 * 100)  # fits: no error


@pytest.mark.slow
def test_importing_weft_does_not_import_dask():
    code = (
        "import sys, weft.app.cli, weft.core.batch, weft.app.batch_cli; weft.app.cli.build_parser(); "
        "print(sorted(m for m in sys.modules if m.split('.')[0] in ('dask', 'distributed')))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]"


@pytest.mark.slow
def test_a_fill_batch_keeps_each_items_bit_depth_as_weft_fill_does(tmp_path, capsys):
    """`weft fill` keeps its image's bit depth (Method.depth_from); a batch over a fill recipe does so
    per item unless --bit-depth is given: a 16-bit frame gives a 16-bit output, an 8-bit one 8 bits,
    each byte for byte what `weft run` writes for that item."""
    photo = load_image(ROOT / "resources" / "gravel.png").image[:40, :40]
    frames = tmp_path / "frames"
    frames.mkdir()
    save_image(frames / "a16.png", photo, bit_depth=16)
    save_image(frames / "b8.png", photo[::-1], bit_depth=8)
    hole = np.zeros((40, 40), np.float32)
    hole[14:24, 12:26] = 1.0
    save_image(tmp_path / "mask.png", hole)
    recipe = {
        "weft": 1,
        "method": "fill",
        "params": {"patch": 7},
        "inputs": {"image": "frames/a16.png", "mask": "mask.png"},
        "seed": 3,
    }
    (tmp_path / "fill.json").write_text(json.dumps(recipe))
    batch = ["batch", tmp_path / "fill.json", "--over", "image", frames, "--workers", "1", "-q"]
    code, _, err = run([*batch, "-o", tmp_path / "out" / "{stem}.png"], capsys)
    assert code == 0, err
    assert load_image(tmp_path / "out" / "a16.png").info.bit_depth == 16
    assert load_image(tmp_path / "out" / "b8.png").info.bit_depth == 8
    for stem in ("a16", "b8"):
        item = dict(recipe, inputs={"image": f"frames/{stem}.png", "mask": "mask.png"})
        (tmp_path / f"{stem}.json").write_text(json.dumps(item))
        ref = tmp_path / "ref" / f"{stem}.png"
        ref.parent.mkdir(exist_ok=True)
        assert run(["run", tmp_path / f"{stem}.json", "-o", ref, "-q"], capsys)[0] == 0
        assert ref.read_bytes() == (tmp_path / "out" / f"{stem}.png").read_bytes()
    # a re-run finds them done (the resume check expects each item's own depth)
    code, _, err = run([*batch, "-o", tmp_path / "out" / "{stem}.png"], capsys)
    assert code == 0 and err.strip() == "0 written, 2 already done", err
    # --bit-depth decides for every item
    code, _, err = run([*batch, "--bit-depth", "8", "-o", tmp_path / "out8" / "{stem}.png"], capsys)
    assert code == 0, err
    assert {load_image(tmp_path / "out8" / f"{s}.png").info.bit_depth for s in ("a16", "b8")} == {8}
