"""Affine model §4: partial correlation, the shaker box and its forced convergence; Fig. 6 fields."""

import numpy as np
import pytest
from weft.core.affine import (
    analyse,
    field_model,
    field_transforms,
    make_prototype,
    match_boundaries,
    render,
    synthesize,
    total_boundary_error,
)
from weft.core.affine.boundary import _Canvas
from weft.core.affine.model import Grid
from weft.core.errors import InvalidParameter
from weft.core.examples import example
from weft.core.image import load_image

from benchmarks.fixtures.procedural import cells


@pytest.fixture(scope="module")
def brick():
    return load_image(example("brick")).image[:160, :160]


@pytest.fixture(scope="module")
def brick_model(brick):
    return analyse(brick)


def test_shaker_never_increases_the_total_boundary_error(brick_model):
    for seed in range(3):
        model, rep = match_boundaries(brick_model, "shaker", iterations=30, per_radius=2, rng=seed)
        errs = np.array(rep.errors)
        assert len(errs) == rep.iterations + 1 and rep.iterations >= 3
        assert np.all(np.diff(errs) <= 1e-9 * errs[0]), errs
        # the schedule: B/4 = 8 for two iterations, then 7, ... and never below 1
        assert rep.radii == [8 - i // 2 for i in range(len(rep.radii))]
        # what is reported is the total of the translations returned
        assert total_boundary_error(model) == pytest.approx(errs[-1], rel=1e-7)  # incremental sums
        assert np.all(np.abs(model.shifts) <= model.grid.radius)
        assert np.all(model.shifts == np.round(model.shifts))


def test_shaker_from_the_analysis_translations_also_descends(brick_model):
    start = total_boundary_error(brick_model.with_shifts(np.round(brick_model.shifts)))
    _, rep = match_boundaries(brick_model, "shaker", start="analysis", rng=0)
    assert rep.errors[0] == pytest.approx(start, rel=1e-9)
    assert np.all(np.diff(rep.errors) <= 1e-9 * rep.errors[0]) and rep.errors[-1] < rep.errors[0]


def test_shaker_ends_when_nothing_moves_or_no_change_is_allowed(brick_model):
    _, rep = match_boundaries(brick_model, "shaker", iterations=500, per_radius=1, rng=0)
    # converged (last iteration moved nothing), or the radius ran out (B/4 = 8 iterations)
    assert rep.moves[-1] == 0 or rep.iterations == 8
    assert rep.iterations <= 8


def test_boundary_matching_improves_continuity(brick_model):
    base = total_boundary_error(brick_model.with_shifts(np.round(brick_model.shifts)))
    partial, rep_p = match_boundaries(brick_model, "partial")
    shaker, rep_s = match_boundaries(brick_model, "shaker", rng=0)
    assert rep_p.iterations == 0 and len(rep_p.errors) == 1
    assert rep_s.errors[-1] < rep_p.errors[0]
    assert rep_s.errors[-1] < base


def test_the_skipping_of_settled_patches_is_exact(brick_model):
    """Patches whose neighbours have not moved are skipped; the result must be the same."""
    proto = brick_model.prototype
    runs = []
    for skip in (True, False):
        canvas = _Canvas(brick_model, proto, brick_model.shifts)
        rng = np.random.default_rng(4)
        canvas.run(np.arange(brick_model.grid.count), canvas.R, skip=False)  # partial pass
        canvas.seen_at[:] = -1
        for it in range(12):
            canvas.run(rng.permutation(brick_model.grid.count), canvas.R - it // 3, skip=skip)
        runs.append((canvas.shifts.copy(), canvas.total_error()))
    np.testing.assert_array_equal(runs[0][0], runs[1][0])
    assert runs[0][1] == pytest.approx(runs[1][1], rel=1e-12)


def test_same_seed_same_result_other_seed_other_order(brick):
    a = synthesize(brick, boundary="shaker", rng=11)
    b = synthesize(brick, boundary="shaker", rng=11)
    c = synthesize(brick, boundary="shaker", rng=12)
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, c)


def test_partial_is_deterministic_without_a_seed(brick):
    np.testing.assert_array_equal(synthesize(brick, boundary="partial"), synthesize(brick, boundary="partial"))


def test_bad_boundary_arguments(brick_model):
    with pytest.raises(InvalidParameter, match="boundary"):
        match_boundaries(brick_model, "wobble")
    with pytest.raises(InvalidParameter, match="shaker_start"):
        match_boundaries(brick_model, "shaker", start="middle")
    with pytest.raises(InvalidParameter, match="iterations"):
        match_boundaries(brick_model, "shaker", iterations=0)


@pytest.mark.parametrize("field", ["none", "swirl", "zoom", "rotate"])
def test_parametric_fields(field):
    grid = Grid(96, 128, 32)
    T = field_transforms(grid, field, 1.0)
    assert T.shape == (grid.count, 2, 2) and np.all(np.isfinite(T))
    if field == "none":
        np.testing.assert_allclose(T, np.broadcast_to(np.eye(2), T.shape))
    if field == "rotate":  # the turn grows from left to right
        first, last = T[0], T[grid.cols - 1]
        assert np.arctan2(first[1, 0], first[0, 0]) < 0 < np.arctan2(last[1, 0], last[0, 0])
    if field == "zoom":  # larger in the middle
        s = np.sqrt(np.abs(np.linalg.det(T)))
        assert s.max() > 1.5 and s.min() < 1.1


def test_field_synthesis_with_the_shaker_box():
    tex = cells(128)
    proto = make_prototype(tex, (32, 32, 64), block=32)
    model = field_model((96, 160), proto, "swirl", block=32)
    out0 = render(model)
    assert out0.shape == (96, 160)
    matched, rep = match_boundaries(model, "shaker", rng=0)
    assert rep.errors[-1] < rep.errors[0]
    out = render(matched)
    assert np.all(np.isfinite(out)) and out.std() > 0.05
    # through the one-call API: a size, auto = shaker
    res = synthesize(tex, field="zoom", size=(80, 64), rng=0)
    assert res.shape == (64, 80)
