"""Warm-up orchestration: each method's kernels once per process, in the order asked, and numba's
compile events (a real compile, never a cache load) seen by ``registry.watch_compiles``."""

import dataclasses
import threading

import numpy as np
import pytest
import weft.core._kernels  # noqa: F401  (installs the compile-event listener)
from numba import njit
from weft.core import registry
from weft.core.jobs import Cancelled, CancelToken


@pytest.fixture
def fake_methods(monkeypatch):
    """Three fake methods whose warm-ups record their calls (the registry's state is restored)."""
    calls = []
    gates = {}
    base = registry.get("fast")
    monkeypatch.setattr(registry, "_warm", set())
    monkeypatch.setattr(registry, "_MODULES", {"a": "x", "b": "x", "c": "x"})
    for name in "abc":

        def warm(name=name):
            calls.append(name)
            if name in gates:
                gates[name].wait(30)

        monkeypatch.setitem(registry._loaded, name, dataclasses.replace(base, name=name, warm_up=warm))
    return calls, gates


def test_warm_up_runs_once_and_is_warm_after(fake_methods):
    calls, _ = fake_methods
    assert not registry.is_warm("a")
    assert registry.warm_up("a") is True
    assert registry.is_warm("a")
    assert registry.warm_up("a") is False
    assert calls == ["a"]


def test_concurrent_warm_up_of_one_method_runs_it_once(fake_methods):
    calls, gates = fake_methods
    gates["a"] = threading.Event()
    results = []
    threads = [threading.Thread(target=lambda: results.append(registry.warm_up("a"))) for _ in range(3)]
    for t in threads:
        t.start()
    gates["a"].set()
    for t in threads:
        t.join(30)
    assert calls == ["a"] and sorted(results) == [False, False, True]


def test_warm_up_all_puts_first_first_skips_warm_ones_and_stops_when_cancelled(fake_methods):
    calls, _ = fake_methods
    registry.warm_up("b")
    assert registry.warm_up_all(first="c") == ["c", "a"]
    assert calls == ["b", "c", "a"]
    token = CancelToken()
    token.cancel()
    registry._warm.clear()
    with pytest.raises(Cancelled):
        registry.warm_up_all(cancel=token)
    assert calls == ["b", "c", "a"]


def test_watch_compiles_sees_a_real_compile_once_and_only_its_thread():
    @njit(nogil=True)
    def add_one(x):
        return x + 1.0

    started = []
    with (
        registry.watch_compiles(on_start=lambda: started.append(threading.get_ident())) as everywhere,
        registry.watch_compiles(this_thread=True) as mine,
    ):
        other = threading.Thread(target=lambda: add_one(np.float32(1)))
        other.start()
        other.join(60)
        assert everywhere.count >= 1 and mine.count == 0  # another thread compiled
        assert started == [other.ident]
        assert add_one(2.0) == 3.0  # a new signature: compiled here
        assert mine.count >= 1 and mine.seconds > 0
        seen = mine.count
        assert add_one(5.0) == 6.0  # already compiled: no event
        assert mine.count == seen
    assert not registry.compiling()


def test_compiling_is_true_only_during_a_compile():
    inside = []

    @njit
    def probe(x):
        return x * 2

    with registry.watch_compiles(on_start=lambda: inside.append(registry.compiling())):
        probe(3)
    assert inside == [True] and not registry.compiling()


def test_warm_up_report_says_what_was_compiled(fake_methods):
    report = registry.warm_up_report("a")
    assert report["method"] == "a" and report["compiled"] == 0 and report["seconds"] >= 0
    assert report["notice"] is None


def test_preparing_text_names_the_method():
    assert registry.preparing_text("fast") == "preparing the fast method — first run only"
