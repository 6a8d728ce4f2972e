"""Jobs too large are refused up front (pixels, memory, running time), in one line."""

from __future__ import annotations

import numpy as np
import pytest
from weft.app import cli
from weft.core import fast, limits, nfpt, quilting
from weft.core.errors import WeftError
from weft.core.image import set_max_pixels
from weft.core.limits import LimitError


@pytest.fixture(autouse=True)
def _restore_limits():
    yield
    limits.set_max_seconds(None)
    set_max_pixels(None)


def _tex(side: int = 64, colour: bool = True) -> np.ndarray:
    rng = np.random.default_rng(0)
    return rng.random((side, side, 3) if colour else (side, side), dtype=np.float32)


def _never_called(_progress) -> None:
    raise AssertionError("the job started: it should have been refused before any work")


def test_quilting_too_long_is_refused_before_any_block():
    tex = _tex(256)
    est = quilting.estimate_seconds(tex.shape, (1024, 1024), [(8, 2)])
    limits.set_max_seconds(est / 2)
    with pytest.raises(LimitError) as info:
        quilting.synthesize(tex, size=(1024, 1024), block=8, overlap=2, progress=_never_called)
    msg = str(info.value)
    assert "\n" not in msg
    assert msg.startswith("quilting of 1024x1024 from a 256x256 texture (29,241 blocks of 8 px) would take about")
    assert "use a larger block" in msg and "WEFT_MAX_SECONDS" in msg
    # at the limit it runs (a cheaper job under the same limit)
    out = quilting.synthesize(tex, size=(64, 64), block=16, overlap=3, rng=1)
    assert out.shape == (64, 64, 3)


def test_iterative_transfer_counts_every_pass():
    tex, target = _tex(64), _tex(128)
    passes = [(b, o) for b, o, _ in quilting.transfer_schedule(5)]
    five = quilting.estimate_seconds(tex.shape, (128, 128), passes)
    one = quilting.estimate_seconds(tex.shape, (128, 128), passes[:1])
    assert five > 4 * one  # the later passes have smaller blocks, so more of them
    limits.set_max_seconds((five + one) / 2)
    quilting.transfer(tex, target, iterations=1, block=31, overlap=21, rng=1)  # one pass fits the limit
    with pytest.raises(
        LimitError,
        match=r"^transfer of 128x128 from a 64x64 texture \(.* blocks of 31 to 9 px in 5 "
        r"passes\) would take about .*fewer iterations",
    ):
        quilting.transfer(tex, target, iterations=5, progress=_never_called)


def test_quilting_estimate_scales_with_blocks_and_texture():
    small = quilting.estimate_seconds((128, 128, 3), (512, 512), [(32, 6)])
    assert quilting.estimate_seconds((128, 128, 3), (1024, 1024), [(32, 6)]) == pytest.approx(4 * small, rel=0.1)
    # four times the blocks, each cheaper (the per-block cost grows with the block: measured)
    assert quilting.estimate_seconds((128, 128, 3), (512, 512), [(16, 3)]) > 2 * small
    assert quilting.estimate_seconds((512, 512, 3), (512, 512), [(32, 6)]) > 1.3 * small  # larger DFTs per block


def test_output_over_the_pixel_limit_is_refused_naming_what_set_it():
    set_max_pixels(10_000)
    with pytest.raises(
        LimitError,
        match=r"^parameter 'size': an output of 200x100 = 0\.0 megapixels exceeds the limit "
        r"of 0\.01 megapixels",
    ):
        quilting.synthesize(_tex(), size=(200, 100), block=16, progress=_never_called)
    with pytest.raises(LimitError, match=r"^parameter 'size': an output of 128x128"):
        quilting.synthesize(_tex(), block=16, mode="random")  # default size: twice the texture
    with pytest.raises(LimitError, match=r"^parameter 'magnify': an output of 256x256"):
        fast.transfer(_tex(), None, mode="superres", magnify=4, progress=_never_called)
    with pytest.raises(LimitError, match=r"^the target: an output of 120x110"):
        fast.transfer(_tex(), _tex(1)[:1, :1].repeat(110, 0).repeat(120, 1), progress=_never_called)
    with pytest.raises(LimitError, match=r"^parameter 'size': an output of 128x128"):
        nfpt.synthesize(_tex(), block=16, overlap=4, progress=_never_called)
    set_max_pixels(None)
    out = fast.transfer(_tex(), None, mode="superres", magnify=2, rng=1)
    assert out.shape == (128, 128, 3)


def test_more_memory_than_available_is_refused(monkeypatch):
    monkeypatch.setattr(limits, "available_memory", lambda: 20 * 2**20)  # 20 MiB free
    target = np.zeros((1024, 1024, 3), np.float32)  # 1 Mpx x 50 B > 20 MiB
    with pytest.raises(
        LimitError,
        match=r"^fast transfer of 1024x1024 needs about 50 MiB of memory, 20 MiB is "
        r"available: make the output smaller$",
    ):
        fast.transfer(_tex(), target, progress=_never_called)
    with pytest.raises(LimitError, match=r"^quilting 1024x1024 from a 64x64 texture needs about"):
        quilting.synthesize(_tex(), size=(1024, 1024), block=32, progress=_never_called)
    monkeypatch.setattr(limits, "available_memory", lambda: None)  # unknown: no check
    assert quilting.synthesize(_tex(), size=(64, 64), block=32, rng=1).shape == (64, 64, 3)


def test_nfpt_too_long_is_refused():
    tex = _tex(128, colour=False)
    est = nfpt.estimate_seconds(tex.shape, (256, 256), 16, 4)
    assert est > 0
    limits.set_max_seconds(est / 2)
    with pytest.raises(
        LimitError,
        match=r"^NFPT synthesis of 256x256 from a 128x128 texture with 16 px patches "
        r"would take about",
    ):
        nfpt.synthesize(tex, size=(256, 256), block=16, overlap=4, progress=_never_called)


def test_max_seconds_from_environment(monkeypatch):
    monkeypatch.setenv("WEFT_MAX_SECONDS", "42")
    assert limits.get_max_seconds() == 42.0
    monkeypatch.setenv("WEFT_MAX_SECONDS", "inf")
    assert limits.get_max_seconds() == float("inf")
    for junk in ("", "soon", "-5", "0"):
        monkeypatch.setenv("WEFT_MAX_SECONDS", junk)
        assert limits.get_max_seconds() == limits.DEFAULT_MAX_SECONDS
    limits.set_max_seconds(3)
    assert limits.get_max_seconds() == 3.0
    for bad in (0, -1, float("nan"), "10", True):
        with pytest.raises(WeftError, match="parameter 'max_seconds'"):
            limits.set_max_seconds(bad)


def test_cli_refuses_a_long_job_in_one_line_and_writes_nothing(tmp_path, capsys, monkeypatch):
    from weft.core.examples import example

    monkeypatch.setenv("WEFT_MAX_SECONDS", "5")
    out = tmp_path / "out.png"
    code = cli.main(
        ["quilt", str(example("gravel")), "--size", "4096x4096", "--block", "4", "--overlap", "1", "-o", str(out)]
    )
    err = capsys.readouterr().err
    assert code == 2 and not out.exists()
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert err.startswith(
        "weft: quilting of 4096x4096 from a 256x256 texture (1,863,225 blocks of 4 px) would take about "
    ), err
    assert "(limit 5.0 s)" in err


def test_available_memory_reads_the_system():
    free = limits.available_memory()
    assert free is None or free > 0


def test_transfer_memory_counts_its_rows_of_spectra(monkeypatch):
    """A transfer keeps two block rows of texture-sized spectra: 2 x 85 x 256² x 4 B = 43 MiB here, on top
    of 50 B per output pixel and 60 B per texture pixel; a synthesis of the same size has no rows."""
    monkeypatch.setattr(limits, "available_memory", lambda: 30 * 2**20)
    tex, target = _tex(256, colour=False), _tex(512, colour=False)
    with pytest.raises(
        LimitError,
        match=r"^quilting 512x512 from a 256x256 texture needs about 59 MiB of memory, "
        r"30 MiB is available: use a smaller target or a smaller part of the texture$",
    ):
        quilting.transfer(tex, target, progress=_never_called)
    monkeypatch.setattr(limits, "available_memory", lambda: 10 * 2**20)
    with pytest.raises(
        LimitError,
        match=r"^quilting 512x512 from a 256x256 texture needs about 14 MiB of memory, "
        r"10 MiB is available: use a smaller size or",
    ):
        quilting.synthesize(tex, size=(512, 512), block=32, progress=_never_called)


# --- the memory a container or ulimit -v allows, not only the host's ----------------------------------


def _fake_system(tmp_path, monkeypatch, cgroup_line: str, files: dict[str, str], meminfo_kib: int = 64 * 2**20):
    proc, fs = tmp_path / "proc", tmp_path / "cgroup"
    (proc / "self").mkdir(parents=True)
    (proc / "meminfo").write_text(f"MemTotal: {2 * meminfo_kib} kB\nMemAvailable: {meminfo_kib} kB\n")
    (proc / "self" / "cgroup").write_text(cgroup_line + "\n")
    for rel, text in files.items():
        (fs / rel).parent.mkdir(parents=True, exist_ok=True)
        (fs / rel).write_text(text)
    monkeypatch.setattr(limits, "_PROC", str(proc))
    monkeypatch.setattr(limits, "_CGROUP_FS", str(fs))
    monkeypatch.setattr(limits, "_address_space_left", lambda: None)


def test_a_cgroup_v2_limit_below_the_hosts_memory_is_what_is_available(tmp_path, monkeypatch):
    _fake_system(
        tmp_path,
        monkeypatch,
        "0::/job",
        {
            "job/memory.max": "629145600\n",
            "job/memory.current": "104857600\n",
            "job/memory.stat": "anon 80000000\ninactive_file 20971520\n",
            "memory.max": "max\n",
        },
    )
    assert limits.available_memory() == 629145600 - (104857600 - 20971520)  # 600 MiB limit, 80 MiB used


def test_a_parent_cgroups_limit_applies_and_the_hosts_when_smaller(tmp_path, monkeypatch):
    _fake_system(
        tmp_path,
        monkeypatch,
        "4:memory:/outer/inner",
        {
            "memory/outer/inner/memory.limit_in_bytes": "9223372036854771712\n",
            "memory/outer/inner/memory.usage_in_bytes": "0\n",
            "memory/outer/memory.limit_in_bytes": str(300 * 2**20),
            "memory/outer/memory.usage_in_bytes": str(100 * 2**20),
        },
    )
    assert limits.available_memory() == 200 * 2**20
    _fake_system(
        tmp_path / "b", monkeypatch, "0::/", {"memory.max": str(8 * 2**30), "memory.current": "0"}, meminfo_kib=2**20
    )
    assert limits.available_memory() == 2**30  # the host has less than the group allows


def test_ulimit_v_bounds_what_is_available(monkeypatch):
    resource = pytest.importorskip("resource")
    monkeypatch.setattr(
        resource,
        "getrlimit",
        lambda which: (
            (limits._vm_size() + 50 * 2**20, resource.RLIM_INFINITY)
            if which == resource.RLIMIT_AS
            else (resource.RLIM_INFINITY, resource.RLIM_INFINITY)
        ),
    )
    assert 45 * 2**20 < limits.available_memory() <= 50 * 2**20


def _memory_cgroup(limit: int):
    """A real cgroup v1 memory group limited to ``limit`` bytes, or a reason it cannot be made here."""
    import os

    root = "/sys/fs/cgroup/memory"
    if os.geteuid() != 0 or not os.path.isfile(os.path.join(root, "memory.limit_in_bytes")):
        return None, "needs root and a cgroup v1 memory controller mounted at /sys/fs/cgroup/memory"
    path = os.path.join(root, f"weft-test-{os.getpid()}")
    try:
        os.mkdir(path)
        with open(os.path.join(path, "memory.limit_in_bytes"), "w") as f:
            f.write(str(limit))
    except OSError as e:
        return None, f"cannot create a memory cgroup here ({e.strerror})"
    return path, None


@pytest.mark.slow
def test_a_job_too_large_for_its_container_is_refused_up_front(tmp_path):
    import os
    import subprocess
    import sys

    from weft.core.image import save_image

    group, reason = _memory_cgroup(600 * 2**20)
    if group is None:
        pytest.skip(reason)
    try:
        rng = np.random.default_rng(0)
        save_image(tmp_path / "tex.png", rng.random((64, 64, 3), dtype=np.float32))
        save_image(tmp_path / "big.png", rng.random((4096, 4096), dtype=np.float32))
        script = f'echo $$ > {group}/cgroup.procs && exec "$@"'
        done = subprocess.run(
            [
                "sh",
                "-c",
                script,
                "sh",
                sys.executable,
                "-c",
                "import sys; from weft.app.cli import main; sys.exit(main())",
                "fast",
                str(tmp_path / "tex.png"),
                "--target",
                str(tmp_path / "big.png"),
                "-o",
                str(tmp_path / "o.png"),
                "-q",
            ],
            capture_output=True,
            text=True,
            timeout=300,
        )
        assert done.returncode == 2, done.stderr
        assert "of memory" in done.stderr and "is available" in done.stderr and done.stderr.count("\n") == 1
        assert not (tmp_path / "o.png").exists()
    finally:
        os.rmdir(group)


# --- estimates fitted to measured runs (benchmarks/limits.py, benchmarks/results/limits.json) ------------


def _colour_png(tmp_path, side: int):
    from weft.core.image import load_image, save_image

    path = tmp_path / "small.png"
    save_image(
        path, load_image(limits.__file__.rsplit("/core/", 1)[0] + "/resources/astronaut.png").image[:side, :side]
    )
    return path


def test_a_colour_uncrop_too_large_for_memory_is_refused_up_front(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(limits, "available_memory", lambda: 500 * 2**20)
    small = _colour_png(tmp_path, 96)
    code = cli.main(["fill", str(small), "--size", "600x600", "-o", str(tmp_path / "o.png"), "-q"])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1, err
    assert err.startswith("weft: fill of a 600x600 canvas (uncrop) needs about ") and "500 MiB is available" in err
    assert not (tmp_path / "o.png").exists()


def test_a_colour_uncrop_too_long_is_refused_up_front(tmp_path, capsys, monkeypatch):
    limits.set_max_seconds(5)
    small = _colour_png(tmp_path, 96)
    code = cli.main(["fill", str(small), "--size", "600x600", "-o", str(tmp_path / "o.png"), "-q"])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and "would take about" in err, err
    assert not (tmp_path / "o.png").exists()


def test_small_quilting_blocks_count_their_per_block_cost(tmp_path, capsys):
    from weft.core.image import save_image

    limits.set_max_seconds(5)
    save_image(tmp_path / "t.png", _tex(128))
    code = cli.main(
        [
            "quilt",
            str(tmp_path / "t.png"),
            "--size",
            "300x300",
            "--block",
            "4",
            "--overlap",
            "1",
            "-o",
            str(tmp_path / "o.png"),
            "-q",
        ]
    )
    err = capsys.readouterr().err
    assert code == 2 and "would take about" in err and err.count("\n") == 1, err
    assert not (tmp_path / "o.png").exists()
