"""The CLI on a first run: a terminal hears that kernels are being prepared (once, then the seconds
tick until the progress bar takes over); a warm run, ``-q`` and a non-terminal stderr hear nothing;
``weft warm-up`` prepares every method in separate processes and says what it did.

The "compile" here is a fake method's warm-up raising the same events numba's compiles raise
(``registry.compile_started/compile_ended``), held open on a ``threading.Event``: no timing."""

import dataclasses
import io
import queue
import threading

import numpy as np
import pytest
import weft.core._kernels  # noqa: F401  (the compile-event listener)
from weft.app.cli import main
from weft.app.terminal import PreparingLine, TerminalProgress
from weft.core import registry
from weft.core.image import save_image
from weft.core.jobs import Progress, ProgressReporter
from weft.core.registry import Result


class TTY(io.StringIO):
    """A stderr that says it is a terminal; ``written`` is set on every write."""

    def __init__(self):
        super().__init__()
        self.written = threading.Event()

    def isatty(self):
        return True

    def write(self, s):
        n = super().write(s)
        self.written.set()
        return n


@pytest.fixture
def texture(tmp_path):
    path = tmp_path / "tex.png"
    save_image(path, np.random.default_rng(0).random((16, 16, 3)).astype(np.float32))
    return path


@pytest.fixture
def fake(monkeypatch):
    """The method 'fast' replaced by a fake whose kernels 'compile' (raise compile events) in its
    warm-up, or, as numba compiles lazily, in its run when nothing warmed it up first; its run
    reports progress over 4 rows."""
    base = registry.get("fast")
    state = {"compiles": True}

    def warm_up():
        if state["compiles"]:
            registry.compile_started()
            registry.compile_ended()

    def run(inputs, params, *, rng, progress, cancel):
        if "fast" not in registry._warm:
            warm_up()
        report = ProgressReporter(progress, "rows", 4)
        for i in range(1, 5):
            report.update(i)
        return Result(inputs["texture"])

    monkeypatch.setitem(registry._loaded, "fast", dataclasses.replace(base, warm_up=warm_up, run=run))
    monkeypatch.setattr(registry, "_warm", set())
    return state


def test_first_run_on_a_terminal_says_it_prepares_then_draws_the_bar(fake, texture, tmp_path, monkeypatch):
    err = TTY()
    monkeypatch.setattr("sys.stderr", err)
    assert main(["fast", str(texture), "-o", str(tmp_path / "o.png")]) == 0
    text = err.getvalue()
    line = "weft: preparing the fast method — first run only (compiling kernels)"
    assert text.startswith(line)
    assert text.count("preparing") == 1
    assert "\nrows" in text.replace("\r", "") and text.endswith("100%\n")
    assert len(line) < 80  # one terminal row: the ticking \r rewrite stays on it


def test_warm_run_quiet_and_non_terminal_say_nothing(fake, texture, tmp_path, monkeypatch, capsys):
    fake["compiles"] = False  # every kernel from the cache: no compile event
    err = TTY()
    monkeypatch.setattr("sys.stderr", err)
    assert main(["fast", str(texture), "-o", str(tmp_path / "o.png")]) == 0
    assert "preparing" not in err.getvalue() and "rows" in err.getvalue()

    fake["compiles"] = True
    registry._warm.clear()
    err = TTY()
    monkeypatch.setattr("sys.stderr", err)
    assert main(["fast", str(texture), "-o", str(tmp_path / "o.png"), "-q"]) == 0
    assert err.getvalue() == ""

    registry._warm.clear()
    monkeypatch.undo()  # stderr back to capsys's (not a terminal)
    monkeypatch.setitem(registry._loaded, "fast", registry._loaded["fast"])
    assert main(["fast", str(texture), "-o", str(tmp_path / "o.png")]) == 0
    assert capsys.readouterr().err == ""


def test_the_preparing_line_ticks_until_the_bar_takes_over(monkeypatch):
    err = TTY()
    monkeypatch.setattr("sys.stderr", err)
    bar = TerminalProgress(True)
    gate = queue.Queue()
    line = PreparingLine("quilt", bar, wait=lambda seconds: gate.get(timeout=30))
    line()
    line()  # said once only
    first = "weft: preparing the quilt method — first run only (compiling kernels)"
    assert err.getvalue() == first
    err.written.clear()
    gate.put(False)  # one tick
    assert err.written.wait(30)
    assert err.getvalue().startswith(first + "\r" + first + " ") and err.getvalue().endswith(" s")
    bar(Progress("rows", 0, 4))
    assert err.getvalue().endswith("\n\rrows           [" + " " * 30 + "]   0%")
    before = err.getvalue()
    gate.put(False)  # the next tick finds the bar in charge: the ticker ends without writing
    line.thread.join(30)
    assert not line.thread.is_alive() and err.getvalue() == before
    bar.close()
    assert err.getvalue().endswith("0%\n")


@pytest.mark.slow
def test_warm_up_command_prepares_every_method_in_processes(monkeypatch, capsys):
    calls = []

    class Pool:  # the real pool spawns interpreters that compile for seconds; its use is what matters
        def __init__(self, max_workers, mp_context):
            calls.append(("pool", max_workers, mp_context.get_start_method()))

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            return False

        def submit(self, fn, name):
            from concurrent.futures import Future

            f = Future()
            calls.append(name)
            f.set_result({"method": name, "seconds": 0.5, "compiled": 3 if name == "quilt" else 0, "notice": None})
            return f

    monkeypatch.setattr("concurrent.futures.ProcessPoolExecutor", Pool)
    assert main(["warm-up", "--jobs", "2"]) == 0
    out = capsys.readouterr().out.splitlines()
    with_warm_up = [m.name for m in registry.methods().values() if m.warm_up is not None]
    assert calls[0] == ("pool", 2, "spawn") and sorted(calls[1:]) == sorted(with_warm_up)
    assert out[0] == f"weft: warming up {len(with_warm_up)} methods, 2 processes at once"
    assert "quilt    compiled 3 functions in 0.5 s" in out
    assert "fast     loaded from the cache in 0.5 s" in out
    assert out[-1].startswith(f"weft: {len(with_warm_up)} methods ready in ")
    assert main(["warm-up", "-q"]) == 0
    assert capsys.readouterr() == ("", "")


@pytest.mark.slow
def test_warm_up_command_for_real_in_processes(tmp_path):
    """The real subcommand (spawned processes, a fresh cache folder: cold) on the two methods with the
    smallest kernels: exit 0, a line per method, the cache filled (a second run loads both)."""
    import os
    import subprocess
    import sys

    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"))
    cmd = [
        sys.executable,
        "-c",
        "import sys; from weft.app.cli import main; sys.exit(main(['warm-up', 'blend', 'rectify', '--jobs', '2']))",
    ]
    first = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=600)
    assert first.returncode == 0, first.stderr
    lines = first.stdout.splitlines()
    assert lines[0] == "weft: warming up 2 methods, 2 processes at once"
    assert sorted(line.split()[0] for line in lines[1:-1]) == ["blend", "rectify"]
    assert all(" compiled " in line for line in lines[1:-1]) and lines[-1].startswith("weft: 2 methods ready in ")
    second = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=600)
    assert second.returncode == 0, second.stderr
    assert second.stdout.count("loaded from the cache") == 2


def test_warm_up_command_refuses_an_unknown_method(capsys):
    assert main(["warm-up", "nope"]) == 2
    assert capsys.readouterr().err.startswith("weft: unknown method 'nope' (known: ")
