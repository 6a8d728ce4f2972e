"""Minimum-error boundary cuts: the cut follows a known low-error path; shapes and errors."""

import numpy as np
import pytest
from weft.core.errors import ImageError, InvalidParameter
from weft.core.seams import min_cut_mask, min_error_path, overlap_error


def _zigzag(h: int, w: int) -> np.ndarray:
    cols = np.empty(h, dtype=np.int64)
    x = 1
    rng = np.random.default_rng(4)
    for y in range(h):
        cols[y] = x
        x = int(np.clip(x + rng.integers(-1, 2), 0, w - 1))
    return cols


def test_vertical_path_follows_the_only_cheap_route():
    h, w = 30, 6
    path = _zigzag(h, w)
    err = np.ones((h, w))
    err[np.arange(h), path] = 0.0
    assert np.array_equal(min_error_path(err), path)
    mask = min_cut_mask(err, left=w)
    # left of the path the existing pixels stay, from the path on the new block shows
    for y in range(h):
        assert not mask[y, : path[y]].any() and mask[y, path[y] :].all()


def test_path_prefers_lower_total_error_not_lower_first_step():
    # a cheap first row that leads into an expensive column must lose to the globally cheapest path
    err = np.full((5, 3), 5.0)
    err[0, 0] = 0.0
    err[1:, 0] = 9.0
    err[:, 2] = 1.0
    assert list(min_error_path(err)) == [2, 2, 2, 2, 2]


def test_l_shaped_cut_joins_the_two_paths_in_the_corner():
    b, ov = 16, 4
    err = np.ones((b, b))
    # a vertical cheap path in column 2 from the bottom up to row 2, then a horizontal one along row 2
    err[2:, 2] = 0.0
    err[2, 2:] = 0.0
    mask = min_cut_mask(err, left=ov, top=ov)
    expected = np.zeros((b, b), dtype=bool)
    expected[2:, 2:] = True
    assert np.array_equal(mask, expected)


def test_right_and_bottom_cuts_keep_the_far_side():
    b = 12
    err = np.ones((b, b))
    err[:, 9] = 0.0  # right strip = columns 8..11
    err[10, :] = 0.0  # bottom strip = rows 8..11
    mask = min_cut_mask(err, right=4, bottom=4)
    assert mask[:10, :10].all()
    assert not mask[:, 10:].any() and not mask[11:, :].any()


def test_no_overlap_means_all_new_and_error_surface():
    assert min_cut_mask(np.zeros((5, 7))).all()
    a = np.zeros((3, 4, 3))
    b = np.full((3, 4, 3), 0.5)
    assert np.allclose(overlap_error(a, b), 0.75)
    with pytest.raises(ImageError, match="shape"):
        overlap_error(a, b[:2])


def test_bad_inputs():
    with pytest.raises(ImageError, match="2-D"):
        min_cut_mask(np.zeros((4, 4, 3)), left=2)
    with pytest.raises(ImageError, match="NaN"):
        min_error_path(np.full((3, 3), np.nan))
    with pytest.raises(InvalidParameter, match=r"parameter 'left' = 9 is outside 0..8"):
        min_cut_mask(np.zeros((8, 8)), left=9)
    with pytest.raises(InvalidParameter, match="'top' = 1.5 must be an integer"):
        min_cut_mask(np.zeros((8, 8)), top=1.5)


def test_accumulated_costs_are_the_kernels_dynamic_program():
    """``accumulated_costs`` (numpy, a stack at once) is E[y, x] = e[y, x] + min of the three below,
    and a trace down it by the kernel's tie rule gives :func:`min_error_path`'s path (tie-heavy
    integer errors, so the tie rules are compared too)."""
    from weft.core.quilting.engine import _trace_numpy
    from weft.core.seams import accumulated_costs, min_error_path

    rng = np.random.default_rng(11)
    err = np.floor(rng.random((5, 30, 7)) * 3)
    acc = accumulated_costs(err)
    for e, a in zip(err, acc, strict=True):
        expect = e.copy()
        for y in range(e.shape[0] - 2, -1, -1):
            below = np.pad(expect[y + 1], 1, constant_values=np.inf)
            expect[y] += np.minimum(np.minimum(below[:-2], below[1:-1]), below[2:])
        assert np.array_equal(a, expect)
    paths = _trace_numpy(acc, np.zeros(5, np.int64), acc[:, 0].argmin(axis=1))
    for e, path in zip(err, paths, strict=True):
        assert np.array_equal(path, min_error_path(e))
