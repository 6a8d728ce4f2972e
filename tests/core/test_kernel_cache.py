"""No cache crash: a numba method still runs when its cache cannot go where numba looks for one.

numba tries ``NUMBA_CACHE_DIR``, the package's ``__pycache__`` and the user's ``~/.cache/numba``;
when none could be written, decorating a kernel raised ``RuntimeError: cannot cache function ...:
no locator available`` (``weft: internal error``, exit 1). Each case runs ``weft blend --mode poisson``
(a numba kernel) in a fresh process, on a copy of the package. The tests run as root in CI, where
file permissions do not stop writes, so unwritability is made of paths that cannot be folders: the
copy's ``weft/core/_kernels/__pycache__`` is a regular file, ``HOME`` and ``NUMBA_CACHE_DIR`` point under
a regular file.
"""

import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from weft.core.image import save_image

ROOT = Path(__file__).resolve().parents[2]
NO_CACHE = "numba can write its cache nowhere"


@pytest.fixture(scope="module")
def setup(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("cache")
    for pkg in ("core", "app"):
        shutil.copytree(ROOT / pkg, tmp / "pkg" / "weft" / pkg, ignore=shutil.ignore_patterns("__pycache__"))
    (tmp / "file").write_text("not a folder")
    rng = np.random.default_rng(0)
    img = rng.random((24, 24, 3)).astype(np.float32)
    save_image(tmp / "fg.png", img)
    save_image(tmp / "bg.png", img[::-1])
    mask = np.zeros((24, 24), np.float32)
    mask[6:18, 6:18] = 1
    save_image(tmp / "mask.png", mask)
    return tmp


def run_blend(setup, *, package_writable=True, home_writable=True, numba_dir_writable=None, tmpdir=None, no_temp=False):
    """``weft blend --mode poisson`` on the package copy; returns (exit code, stderr, env)."""
    pkg = setup / "pkg"
    cache = pkg / "weft" / "core" / "_kernels" / "__pycache__"
    if cache.is_dir():
        shutil.rmtree(cache)
    elif cache.exists():
        cache.unlink()
    if not package_writable:
        cache.write_text("a file where numba wants its folder")
    env = {k: v for k, v in os.environ.items() if k not in ("NUMBA_CACHE_DIR", "XDG_CACHE_HOME", "PYTHONPATH")}
    home = setup / "home"
    env["HOME"] = str(home) if home_writable else str(setup / "file" / "home")
    if numba_dir_writable is not None:
        env["NUMBA_CACHE_DIR"] = str(setup / "numba") if numba_dir_writable else str(setup / "file" / "numba")
    env["TMPDIR"] = str(tmpdir if tmpdir is not None else setup / "tmp")
    Path(env["TMPDIR"]).mkdir(exist_ok=True)
    env["PYTHONPATH"] = str(pkg)
    patch = (
        "import weft.core._kernels as k; k.fallback_cache_root = lambda: " + repr(str(setup / "file" / "t")) + "; "
        if no_temp
        else ""
    )
    code = (
        f"import sys; {patch}from weft.app.cli import main; sys.exit(main(['blend', {str(setup / 'fg.png')!r}, "
        f"{str(setup / 'bg.png')!r}, '--mask', {str(setup / 'mask.png')!r}, '--mode', 'poisson', "
        f"'-o', {str(setup / 'out.png')!r}]))"
    )
    r = subprocess.run([sys.executable, "-c", code], cwd=setup, env=env, capture_output=True, text=True, timeout=300)
    assert (setup / "out.png").exists() or r.returncode != 0
    return r.returncode, r.stderr, env


@pytest.mark.slow
def test_unwritable_numba_cache_dir_runs(setup):
    code, err, _ = run_blend(setup, numba_dir_writable=False)
    assert code == 0, err
    assert err == ""
    assert list(
        (setup / "pkg" / "weft" / "core" / "_kernels" / "__pycache__").glob("poisson.poisson_cg-*.nbi")
    )  # numba's next folder


@pytest.mark.slow
def test_unwritable_package_folder_runs(setup):
    code, err, _ = run_blend(setup, package_writable=False)
    assert code == 0, err
    assert err == ""


@pytest.mark.slow
def test_unwritable_home_runs(setup):
    code, err, _ = run_blend(setup, home_writable=False)
    assert code == 0, err
    assert err == ""


@pytest.mark.slow
def test_nothing_writable_falls_back_to_a_private_temp_folder_that_stays_warm(setup):
    tmpdir = setup / "tmp-all"
    code, err, _ = run_blend(
        setup, package_writable=False, home_writable=False, numba_dir_writable=False, tmpdir=tmpdir
    )
    assert code == 0, err  # was: weft: internal error: RuntimeError: cannot cache function ...: no locator
    assert err == ""
    folder = tmpdir / f"weft-numba-{os.getuid()}"
    assert folder.is_dir() and (folder.stat().st_mode & 0o777) == 0o700
    index = list(folder.glob("*/poisson.poisson_cg-*.nbi"))
    assert index
    stamp = index[0].stat().st_mtime_ns
    code, err, _ = run_blend(
        setup, package_writable=False, home_writable=False, numba_dir_writable=False, tmpdir=tmpdir
    )
    assert code == 0 and err == ""
    assert index[0].stat().st_mtime_ns == stamp  # loaded from there, not compiled and saved again


@pytest.mark.slow
def test_a_temp_folder_open_to_others_is_not_used(setup):
    tmpdir = setup / "tmp-shared"
    folder = tmpdir / f"weft-numba-{os.getuid()}"
    folder.mkdir(parents=True)
    folder.chmod(0o777)  # someone could plant cache files (pickles) there
    code, err, _ = run_blend(
        setup, package_writable=False, home_writable=False, numba_dir_writable=False, tmpdir=tmpdir
    )
    assert code == 0, err
    assert err.startswith("weft: " + NO_CACHE)
    assert not list(folder.iterdir())


@pytest.mark.slow
def test_no_writable_folder_at_all_runs_uncached_with_a_one_line_notice(setup):
    code, err, _ = run_blend(setup, package_writable=False, home_writable=False, numba_dir_writable=False, no_temp=True)
    assert code == 0, err
    lines = err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("weft: " + NO_CACHE)
    assert lines[0].endswith("kernels are compiled on every run")


def _hammer(folder):
    """8 threads save 10 signatures each of one function's cache at once; the keys that read back
    wrong or not at all."""
    import threading

    from numba.core.caching import IndexDataCacheFile

    def work(i):
        f = IndexDataCacheFile(str(folder), "kernel-1.py311", "stamp")
        for j in range(10):
            f.save((i, j), f"code for {i} {j}")

    threads = [threading.Thread(target=work, args=(i,)) for i in range(8)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(60)
    check = IndexDataCacheFile(str(folder), "kernel-1.py311", "stamp")
    return [(i, j) for i in range(8) for j in range(10) if check.load((i, j)) != f"code for {i} {j}"]


def test_concurrent_cache_saves_never_cross_signatures(tmp_path):
    import weft.core._kernels  # noqa: F401  (the lock around numba's saves)

    assert _hammer(tmp_path) == []


def _cut_cache_files(folder: Path) -> int:
    """Cut every numba cache file under ``folder`` to half its size, as a power cut can; how many."""
    files = [p for p in folder.rglob("*") if p.suffix in (".nbi", ".nbc")]
    for p in files:
        data = p.read_bytes()
        p.write_bytes(data[: len(data) // 2])
    return len(files)


@pytest.mark.slow
def test_a_cache_cut_short_is_dropped_recompiled_and_said_once(setup):
    code, err, _ = run_blend(setup, numba_dir_writable=True)
    assert code == 0 and err == "", err
    assert _cut_cache_files(setup / "numba") > 0
    # (run_blend clears the package's own __pycache__, so the damaged NUMBA_CACHE_DIR is what loads)
    code, err, _ = run_blend(setup, numba_dir_writable=True)
    assert code == 0, err  # was: exit 1, EOFError: Ran out of input, on every run
    lines = err.splitlines()
    assert lines and all(
        line.startswith("weft: numba's cache of ") and "dropped and compiled again" in line for line in lines
    ), err
    assert any("poisson" in line for line in lines)
    code, err, _ = run_blend(setup, numba_dir_writable=True)  # repaired: loads quietly
    assert code == 0 and err == "", err


@pytest.mark.slow
def test_warm_up_repairs_a_damaged_cache(setup):
    env = {k: v for k, v in os.environ.items() if k not in ("NUMBA_CACHE_DIR", "PYTHONPATH")}
    env.update(NUMBA_CACHE_DIR=str(setup / "numba-warm"), PYTHONPATH=str(setup / "pkg"), HOME=str(setup / "home"))
    cmd = [sys.executable, "-c", "import sys; from weft.app.cli import main; sys.exit(main(['warm-up', 'blend']))"]
    first = subprocess.run(cmd, cwd=setup, env=env, capture_output=True, text=True, timeout=300)
    assert first.returncode == 0, first.stderr
    assert _cut_cache_files(setup / "numba-warm") > 0
    again = subprocess.run(cmd, cwd=setup, env=env, capture_output=True, text=True, timeout=300)
    assert again.returncode == 0, again.stderr  # was: warm-up of blend failed: EOFError
    assert "dropped and compiled again" in again.stderr and "Traceback" not in again.stderr
