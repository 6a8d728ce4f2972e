"""numba kernel of the minimum-error boundary cut (``weft.core.seams``), shared by quilting's
``place_block`` and the NFPT synthesis.

* :func:`cut_mask` -- the cut of one block: dynamic programming over the overlap strips, the
  vertical and the horizontal cut joined at the best corner pixel.

Compile cost is part of the design: a horizontal cut is the vertical program run on a C-contiguous
transposed copy (not on ``err.T``, whose F layout compiled every helper a second time), and the
helpers are never called with a literal integer (numba compiles a specialisation per literal
value: ``_trace_down(..., 0)`` and ``_trace_down(..., c0)`` would be two). ``zero`` below is an int64
that numba cannot see as the constant 0. So each helper compiles once.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def _vertical_acc(err, c0, c1):
    """Accumulated cost from the bottom row up, columns [c0, c1): E[y] = e[y] + min of 3 below."""
    h = err.shape[0]
    w = c1 - c0
    acc = np.empty((h, w), dtype=np.float64)
    for x in range(w):
        acc[h - 1, x] = err[h - 1, c0 + x]
    for y in range(h - 2, -1, -1):
        for x in range(w):
            m = acc[y + 1, x]
            if x > 0 and acc[y + 1, x - 1] < m:
                m = acc[y + 1, x - 1]
            if x < w - 1 and acc[y + 1, x + 1] < m:
                m = acc[y + 1, x + 1]
            acc[y, x] = err[y, c0 + x] + m
    return acc


@njit(cache=True, nogil=True)
def _trace_down(acc, y_start, x_start, path, c0):
    """Follow ``acc`` (from _vertical_acc) downwards from (y_start, x_start); path[y] = column + c0."""
    h, w = acc.shape
    x = x_start
    path[y_start] = x + c0
    for y in range(y_start + 1, h):
        best = x
        m = acc[y, x]
        if x > 0 and acc[y, x - 1] < m:
            m = acc[y, x - 1]
            best = x - 1
        if x < w - 1 and acc[y, x + 1] < m:
            best = x + 1
        x = best
        path[y] = x + c0


@njit(cache=True, nogil=True)
def cut_mask(err, top, left, right, bottom, mask):
    """Minimum-error boundary cut of a block; ``mask[y, x] = 1`` where the new block shows.

    ``err`` (h, w) float64, C-contiguous, is the squared difference between the existing pixels and
    the new block; only the overlap strips are read: rows [0, top), columns [0, left), columns
    [w-right, w), rows [h-bottom, h). The left and top cuts are one path through the L-shaped
    overlap: both dynamic programs end in the top-left corner, and the corner pixel minimising the
    sum of the two accumulated costs joins them. Right and bottom cuts (tileable output) are
    separate paths and the new region is the intersection of the four sides. Path pixels belong to
    the new block. A horizontal cut is the vertical program on the transpose (``errt``; ``et[x, y]``
    is the cost from the right edge leftwards, ties: the neighbour above wins over the one below).
    """
    h, w = err.shape
    zero = h - h  # an int64 0 (a literal 0 would compile the helpers once more)
    for y in range(h):
        for x in range(w):
            mask[y, x] = 1
    errt = np.empty((w, h), dtype=np.float64)
    if top > 0 or bottom > 0:
        for y in range(h):
            for x in range(w):
                errt[x, y] = err[y, x]
    if left > 0 and top > 0:
        ev = _vertical_acc(err, zero, left)
        et = _vertical_acc(errt, zero, top)
        best = np.inf
        r = zero
        c = zero
        for y in range(top):
            for x in range(left):
                v = ev[y, x] + et[x, y] - err[y, x]
                if v < best:
                    best = v
                    r = y
                    c = x
        vpath = np.empty(h, dtype=np.int64)
        hpath = np.empty(w, dtype=np.int64)
        _trace_down(ev, r, c, vpath, zero)
        _trace_down(et, c, r, hpath, zero)
        for y in range(h):
            for x in range(w):
                a = x >= vpath[y] if y >= r else x >= c
                b = y >= hpath[x] if x >= c else y >= r
                if not (a and b):
                    mask[y, x] = 0
    elif left > 0:
        ev = _vertical_acc(err, zero, left)
        x0 = zero
        for x in range(left):
            if ev[0, x] < ev[0, x0]:
                x0 = x
        vpath = np.empty(h, dtype=np.int64)
        _trace_down(ev, zero, x0, vpath, zero)
        for y in range(h):
            for x in range(vpath[y]):
                mask[y, x] = 0
    elif top > 0:
        et = _vertical_acc(errt, zero, top)
        y0 = zero
        for y in range(top):
            if et[0, y] < et[0, y0]:
                y0 = y
        hpath = np.empty(w, dtype=np.int64)
        _trace_down(et, zero, y0, hpath, zero)
        for x in range(w):
            for y in range(hpath[x]):
                mask[y, x] = 0
    if right > 0:
        c0 = w - right
        ev = _vertical_acc(err, c0, w)
        x0 = zero
        for x in range(right):
            if ev[0, x] < ev[0, x0]:
                x0 = x
        vpath = np.empty(h, dtype=np.int64)
        _trace_down(ev, zero, x0, vpath, c0)
        for y in range(h):
            for x in range(vpath[y] + 1, w):
                mask[y, x] = 0
    if bottom > 0:
        r0 = h - bottom
        et = _vertical_acc(errt, r0, h)
        y0 = zero
        for y in range(bottom):
            if et[0, y] < et[0, y0]:
                y0 = y
        hpath = np.empty(w, dtype=np.int64)
        _trace_down(et, zero, y0, hpath, r0)
        for x in range(w):
            for y in range(hpath[x] + 1, h):
                mask[y, x] = 0
