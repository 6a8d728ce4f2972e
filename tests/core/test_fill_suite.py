"""The public fill suite's cases (benchmarks/fill_suite_cases.py): enough of them, built the same way
every time, split once by name, covering the kinds of hole the suite promises."""

import numpy as np

from benchmarks.fill_suite_cases import CASES, by_name, half


def test_the_suite_has_48_cases_or_more_with_unique_names_in_two_halves():
    names = [c.name for c in CASES]
    assert len(names) >= 48 and len(set(names)) == len(names)
    halves = {c.half for c in CASES}
    assert halves == {"tuning", "check"}
    assert all(half(n) == by_name()[n].half for n in names)  # the split is a function of the name alone


def test_cases_are_deterministic_and_cover_the_hole_kinds():
    a, b = by_name()["gravel-blob"].build(), by_name()["gravel-blob"].build()
    assert np.array_equal(a.hole, b.hole) and np.array_equal(a.image, b.image)
    kinds = {"blob", "stroke", "rect", "several", "large", "border", "uncrop-right", "uncrop-two", "uncrop-all"}
    assert all(any(k in c.name for c in CASES) for k in kinds)
    for c in CASES:
        if "large" in c.name:
            assert 0.15 <= c.build().hole.mean() <= 0.25, c.name
    spoon = by_name()["coffee-spoon-uncrop"].build()  # an uncrop beside an interior hole
    assert spoon.extend == (0, 0, 64, 0) and spoon.part(spoon.hole).any()
    cat = by_name()["chelsea-eye-alpha"].build()  # an RGBA picture whose transparent pixels are the hole
    assert cat.alpha and cat.truth.ndim == 3
