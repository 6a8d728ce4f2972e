"""The numpy engine: the quilting kernels' selection rules, cut and ``place_block`` (no Poisson
band), step for step in numpy, pixel for pixel the same as the numba kernels of
``weft.core._kernels.quilting`` and ``weft.core._kernels.seams`` (a test checks it).

The quilting pass (``weft.core.quilting.engine``) runs these for small syntheses while numba is not
loaded yet: they take the kernels' arguments, so the pass calls either set alike.
"""

from __future__ import annotations

import numpy as np

from ..seams import accumulated_costs
from . import codes as _K  # the kernel's array codes, without importing numba (a test checks it)


def _splitmix_numpy(seed: int, n: int) -> np.ndarray:
    """The kernel's splitmix64 outputs 1..n for ``seed`` (uint64 arithmetic wraps, as in numba)."""
    golden = np.uint64(0x9E3779B97F4A7C15)
    with np.errstate(over="ignore"):
        z = np.uint64(seed) + golden * np.arange(1, n + 1, dtype=np.uint64)
        z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
        z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    return z ^ (z >> np.uint64(31))


def _cost_numpy(cross, sq, const):
    ph, pw = sq.shape
    cost = sq.astype(np.float64) - 2.0 * cross[:ph, :pw].astype(np.float64) + const
    return np.maximum(cost, 0.0).ravel()


def _choose_best_numpy(cross, sq, const, cost_buf=None) -> int:
    return int(np.argmin(_cost_numpy(cross, sq, const)))


def _choose_tol_numpy(cross, sq, const, cost_buf, tol: int, u: float) -> int:
    cost = _cost_numpy(cross, sq, const)
    k = min(tol, cost.size)
    kth = np.partition(cost, k - 1)[k - 1]
    order = np.concatenate([np.flatnonzero(cost < kth), np.flatnonzero(cost == kth)])
    return int(order[min(int(u * k), k - 1)])


def _best_k_numpy(cross, sq, const, cost_buf, k: int, out: np.ndarray) -> int:
    cost = _cost_numpy(cross, sq, const)
    k = min(k, cost.size)
    kth = np.partition(cost, k - 1)[k - 1]
    order = np.concatenate([np.flatnonzero(cost < kth), np.flatnonzero(cost == kth)])[:k]
    out[:k] = order
    return k


def _seam_error_numpy(err: np.ndarray, mask: np.ndarray) -> float:
    """The kernel's ``seam_error`` (summed in the same order)."""
    m = mask.astype(bool)
    off = np.zeros_like(m)  # a 4-neighbour inside the block keeps the old pixel
    off[1:] |= ~m[:-1]
    off[:-1] |= ~m[1:]
    off[:, 1:] |= ~m[:, :-1]
    off[:, :-1] |= ~m[:, 1:]
    vals = err[m & off]
    return float(np.cumsum(vals)[-1]) if vals.size else 0.0


def _choose_epsilon_numpy(cross, sq, const, cost_buf, eps: float, u: float) -> int:
    cost = _cost_numpy(cross, sq, const)
    thr = (1.0 + eps) * max(float(cost.min()), 0.0)
    cand = np.flatnonzero(cost <= thr)
    return int(cand[min(int(u * len(cand)), len(cand) - 1)])


def _choose_sampled_numpy(cross, sq, const, cost_buf, u: float, seed: int) -> int:
    cost = _cost_numpy(cross, sq, const)
    n = cost.size
    z = _splitmix_numpy(int(seed), n + 1)
    limit = np.uint64(int(_K.SAMPLE_FRACTION * 18446744073709551615.0))
    idx = np.flatnonzero(z[:n] < limit)
    if idx.size == 0:
        idx = np.array([int(z[n] % np.uint64(n))])
    k = max(1, int(np.ceil(_K.TOP_FRACTION * idx.size)))
    order = np.argsort(cost[idx], kind="stable")
    return int(idx[order[min(int(u * k), k - 1)]])


def _vertical_accs_numpy(strips: list[np.ndarray]) -> list[np.ndarray]:
    """:func:`weft.core.seams.accumulated_costs` of each (K, h, w) stack of ``strips``; stacks of one shape (a
    square block's left and transposed top strips) run as one program."""
    if len(strips) > 1 and all(s.shape == strips[0].shape for s in strips):
        acc = accumulated_costs(np.concatenate(strips))
        k = strips[0].shape[0]
        return [acc[i * k : (i + 1) * k] for i in range(len(strips))]
    return [accumulated_costs(s) for s in strips]


def _trace_scalar(acc: np.ndarray, y_start, x_start) -> np.ndarray:
    """:func:`_trace_numpy` by scalar steps on Python floats: cheaper for a small stack."""
    k, h, w = acc.shape
    rows_k = acc.tolist()
    out = []
    for i in range(k):
        rows, x, y0 = rows_k[i], int(x_start[i]), int(y_start[i])
        path = [0] * h
        path[y0] = x
        for y in range(y0 + 1, h):
            r = rows[y]
            best, m = x, r[x]
            if x > 0 and r[x - 1] < m:
                m, best = r[x - 1], x - 1
            if x < w - 1 and r[x + 1] < m:
                best = x + 1
            x = best
            path[y] = x
        out.append(path)
    return np.array(out, dtype=np.int64).reshape(k, h)


def _trace_numpy(acc: np.ndarray, y_start, x_start) -> np.ndarray:
    """The kernel's ``_trace_down`` for a stack (K, h, w), each from its own (y_start, x_start);
    the path is 0 above its start.

    Each cell's step into it from the row above (-1, 0 or +1: the kernel's choice, the centre first,
    then the left if strictly less, then the right if strictly less than both) is found for the
    whole stack at once; the walk then takes one gather a row for all K paths (cheaper than scalar
    steps per path for the seam rule's many candidates; :func:`_trace_scalar` takes small stacks,
    K x h <= 256)."""
    k, h, w = acc.shape
    if k * h <= 256:
        return _trace_scalar(acc, y_start, x_start)
    inf = np.full((k, h, 1), np.inf)
    left = np.concatenate([inf, acc[:, :, :-1]], axis=2)
    right = np.concatenate([acc[:, :, 1:], inf], axis=2)
    go_left = left < acc
    m = np.where(go_left, left, acc)
    step = np.where(right < m, 1, np.where(go_left, -1, 0))
    y_start = np.asarray(y_start, dtype=np.int64)
    before = np.arange(h)[None, :] <= y_start[:, None]  # (K, h): rows a path has not entered yet
    step[before] = 0  # it stays in its start column until its start row
    nxt = (step + np.arange(w)).ravel()  # at [i, y, x]: the column path i at (y - 1, x) moves to in row y
    x = np.asarray(x_start, dtype=np.int64).copy()
    y0 = int(y_start.min())
    path = np.zeros((h, k), dtype=np.int64)
    path[y0] = x
    base = np.arange(k) * (h * w)
    for y in range(y0 + 1, h):
        x = path[y] = nxt[base + y * w + x]
    path = path.T.copy()
    path[np.arange(h)[None, :] < y_start[:, None]] = 0
    return path


def _cut_mask_numpy(err: np.ndarray, top: int, left: int, right: int, bottom: int) -> np.ndarray:
    """The kernel's ``cut_mask`` in numpy (horizontal cuts by transposition), for one error surface
    (h, w) or a stack of them (K, h, w) (the seam rule's candidates, cut together). The dynamic
    programs of all sides run together when their strips have one shape (see
    :func:`_vertical_accs_numpy`)."""
    if err.ndim == 2:
        return _cut_mask_numpy(err[None], top, left, right, bottom)[0]
    k, h, w = err.shape
    mask = np.ones((k, h, w), dtype=bool)
    yy, xx = np.arange(h)[:, None], np.arange(w)[None, :]
    zero = np.zeros(k, dtype=np.int64)
    strips, sides = [], []
    if left > 0:
        strips.append(err[:, :, :left])
        sides.append("left")
    if top > 0:
        strips.append(err[:, :top, :].transpose(0, 2, 1))
        sides.append("top")  # (K, w, top): rows = columns
    if right > 0:
        strips.append(err[:, :, w - right :])
        sides.append("right")
    if bottom > 0:
        strips.append(err[:, h - bottom :, :].transpose(0, 2, 1))
        sides.append("bottom")
    accs = dict(zip(sides, _vertical_accs_numpy(strips), strict=True))
    if left > 0 and top > 0:
        ev, eh = accs["left"], accs["top"]
        corner = ev[:, :top, :left] + eh[:, :left, :top].transpose(0, 2, 1) - err[:, :top, :left]
        r, c = np.divmod(corner.reshape(k, -1).argmin(axis=1), left)
        vpath = _trace_numpy(ev, r, c)
        hpath = _trace_numpy(eh, c, r)
        r3, c3 = r[:, None, None], c[:, None, None]
        a = np.where(yy >= r3, xx >= vpath[:, :, None], xx >= c3)
        b = np.where(xx >= c3, yy >= hpath[:, None, :], yy >= r3)
        mask &= a & b
    elif left > 0:
        ev = accs["left"]
        mask &= xx >= _trace_numpy(ev, zero, ev[:, 0].argmin(axis=1))[:, :, None]
    elif top > 0:
        eh = accs["top"]
        mask &= yy >= _trace_numpy(eh, zero, eh[:, 0].argmin(axis=1))[:, None, :]
    if right > 0:
        ev = accs["right"]
        mask &= xx <= (_trace_numpy(ev, zero, ev[:, 0].argmin(axis=1)) + (w - right))[:, :, None]
    if bottom > 0:
        eh = accs["bottom"]
        mask &= yy <= (_trace_numpy(eh, zero, eh[:, 0].argmin(axis=1)) + (h - bottom))[:, None, :]
    return mask


def _make_template_numpy(
    canvas,
    prev,
    corr_t,
    y0,
    x0,
    b,
    top,
    left,
    right,
    bottom,
    wrap,
    w_overlap,
    w_prev,
    w_corr,
    mean,
    mean_c,
    tbuf,
    tcorr,
):
    """The kernel's ``make_template`` for synthesis (overlap term only), in numpy (same values)."""
    if w_prev or w_corr:
        raise RuntimeError(
            "internal: the numpy engine quilts synthesis only (_quilt_pass never sends it transfer terms)"
        )
    hc, wc, nc = canvas.shape
    iy = (y0 + np.arange(b)) % hc
    ix = (x0 + np.arange(b)) % wc
    m = np.zeros((b, b), dtype=bool)
    m[:top] = m[:, :left] = True
    m[:, b - right :] = True
    m[b - bottom :] = True
    o = canvas[np.ix_(iy, ix)].astype(np.float64) - mean
    v = np.where(m[..., None], w_overlap * o, 0.0)
    tbuf[:, :b, :b] = v.transpose(2, 0, 1)
    terms = (v * o)[m]  # (w o) o in the kernel's loop order: row, column, channel
    return float(np.cumsum(terms.ravel())[-1]) if terms.size else 0.0


def _block_errors_numpy(canvas, filled, tex, ip, positions) -> np.ndarray:
    """The kernel's ``block_error`` in numpy for the block of ``ip`` taken from each source
    position ``(sy, sx)`` of ``positions``: a (K, B, B) stack."""
    hc, wc, nc = canvas.shape
    b = int(ip[_K.P_B])
    y0, x0 = int(ip[_K.P_Y0]), int(ip[_K.P_X0])
    top, left, right, bottom = (int(ip[i]) for i in (_K.P_TOP, _K.P_LEFT, _K.P_RIGHT, _K.P_BOTTOM))
    iy = (y0 + np.arange(b)) % hc
    ix = (x0 + np.arange(b)) % wc
    blocks = np.stack([tex[sy : sy + b, sx : sx + b] for sy, sx in positions])
    d = canvas[np.ix_(iy, ix)][None] - blocks
    e = (d * d).astype(np.float64).sum(axis=3)
    strips = np.zeros((b, b), dtype=bool)
    strips[:top] = strips[:, :left] = True
    strips[:, b - right :] = True
    strips[b - bottom :] = True
    e[:, ~(strips & (filled[np.ix_(iy, ix)] != 0))] = 0.0
    return e


def _block_error_numpy(canvas, filled, tex, ip, err: np.ndarray) -> None:
    """The kernel's ``block_error`` in numpy, into ``err``."""
    err[...] = _block_errors_numpy(canvas, filled, tex, ip, [(int(ip[_K.P_SY]), int(ip[_K.P_SX]))])[0]


def _seam_errors_numpy(err: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """:func:`_seam_error_numpy` of a stack (K, h, w) at once (the same sums: the cumulative sum
    in row-major order with zeros between the terms adds the same terms in the same order)."""
    m = mask.astype(bool)
    off = np.zeros_like(m)
    off[:, 1:] |= ~m[:, :-1]
    off[:, :-1] |= ~m[:, 1:]
    off[:, :, 1:] |= ~m[:, :, :-1]
    off[:, :, :-1] |= ~m[:, :, 1:]
    vals = np.where(m & off, err, 0.0).reshape(len(err), -1)
    return np.cumsum(vals, axis=1)[:, -1]


def _by_seam_numpy(
    cross, sq, const, cost_buf, pool, candidates, canvas, filled, tex, ip, err, mask, *kernels_and_pw
) -> int:
    """:func:`_by_seam` in numpy, the candidates' cuts computed together (same choice, the
    winner's cut left in ``mask``)."""
    pw = kernels_and_pw[-1]
    n = _best_k_numpy(cross, sq, const, cost_buf, pool, candidates)
    cands = [int(c) for c in candidates[:n]]
    errs = _block_errors_numpy(canvas, filled, tex, ip, [divmod(c, pw) for c in cands])
    masks = _cut_mask_numpy(errs, *(int(ip[i]) for i in (_K.P_TOP, _K.P_LEFT, _K.P_RIGHT, _K.P_BOTTOM)))
    best = int(np.argmin(_seam_errors_numpy(errs, masks)))
    mask[...] = masks[best]
    return cands[best]


def _cut_mask_into_numpy(err, top, left, right, bottom, mask) -> None:
    """The kernel's ``cut_mask`` signature: the cut of ``err`` written into ``mask``."""
    mask[...] = _cut_mask_numpy(err, int(top), int(left), int(right), int(bottom))


def _place_block_numpy(canvas, filled, tex, ip, mask, *work):
    """The kernel's ``place_block`` (no Poisson band), in numpy (same pixels): in min-cut mode a
    block with overlaps pastes where ``mask`` (the caller's cut) is 1.

    The other arguments are the kernel's work buffers (the Poisson band's), unused here.
    """
    hc, wc, nc = canvas.shape
    b = int(ip[_K.P_B])
    y0, x0 = int(ip[_K.P_Y0]), int(ip[_K.P_X0])
    top, left, right, bottom = (int(ip[i]) for i in (_K.P_TOP, _K.P_LEFT, _K.P_RIGHT, _K.P_BOTTOM))
    sy, sx = int(ip[_K.P_SY]), int(ip[_K.P_SX])
    if y0 + b <= hc and x0 + b <= wc:  # the block lies inside the canvas: views
        iy, ix = slice(y0, y0 + b), slice(x0, x0 + b)
    else:  # a tileable canvas's last blocks wrap around
        iy, ix = np.ix_((y0 + np.arange(b)) % hc, (x0 + np.arange(b)) % wc)
    block = tex[sy : sy + b, sx : sx + b]
    if ip[_K.P_MODE] == _K.MODE_MINCUT and (top or left or right or bottom):
        m = mask.astype(bool)
        canvas[iy, ix] = np.where(m[..., None], block, canvas[iy, ix])
        f = filled[iy, ix]
        f[m] = 1
        filled[iy, ix] = f
    else:
        canvas[iy, ix] = block
        filled[iy, ix] = 1
