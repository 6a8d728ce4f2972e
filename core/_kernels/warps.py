"""numba kernel of the Beier-Neely feature-based field morph, shared by the rectification warps
(``weft.core.rectify.warps``: field morph and view morphing) and the NFPT method that uses them.

* :func:`field_map` -- the morph as a backward map: for every destination pixel, where to sample
  the source; optionally behind a pre-homography and before a post-homography (the pre-warp and
  post-warp of view morphing).
"""

from __future__ import annotations

import numpy as np
from numba import njit

INVALID = -1.0e6  # a map coordinate that samples nothing (outside every image)


@njit(cache=True, nogil=True)
def field_map(dst_lines, src_lines, a, b, p, pre, post, map_x, map_y):
    """Backward map of the Beier-Neely field morph, with an optional pre/post homography.

    For destination pixel X = (x, y): Y = pre(X); for every line pair i (destination P_i Q_i,
    source P'_i Q'_i) ``u = (Y - P).(Q - P) / |Q - P|^2``, ``v = (Y - P).perp(Q - P) / |Q - P|``,
    ``Y'_i = P' + u (Q' - P') + v perp(Q' - P') / |Q' - P'|``; the weights are
    ``(|Q - P|^p / (a + dist))^b`` with ``dist`` the distance from Y to the segment PQ; the source
    point is ``Y + sum w_i (Y'_i - Y) / sum w_i``, then ``post`` maps it to the source image.
    ``pre``/``post`` are 3x3 (identity for a plain field morph); a point that a homography sends
    to or behind infinity (third coordinate <= 1e-12) is marked with ``INVALID``.
    """
    h, w = map_x.shape
    n = dst_lines.shape[0]
    px = np.empty(n)
    py = np.empty(n)
    dx = np.empty(n)
    dy = np.empty(n)
    len2 = np.empty(n)
    length = np.empty(n)
    spx = np.empty(n)
    spy = np.empty(n)
    sdx = np.empty(n)
    sdy = np.empty(n)
    slen = np.empty(n)
    lw = np.empty(n)
    for i in range(n):
        px[i] = dst_lines[i, 0]
        py[i] = dst_lines[i, 1]
        dx[i] = dst_lines[i, 2] - dst_lines[i, 0]
        dy[i] = dst_lines[i, 3] - dst_lines[i, 1]
        len2[i] = dx[i] * dx[i] + dy[i] * dy[i]
        length[i] = np.sqrt(len2[i])
        spx[i] = src_lines[i, 0]
        spy[i] = src_lines[i, 1]
        sdx[i] = src_lines[i, 2] - src_lines[i, 0]
        sdy[i] = src_lines[i, 3] - src_lines[i, 1]
        slen[i] = np.sqrt(sdx[i] * sdx[i] + sdy[i] * sdy[i])
        lw[i] = length[i] ** p
    for yy in range(h):
        for xx in range(w):
            wz = pre[2, 0] * xx + pre[2, 1] * yy + pre[2, 2]
            if wz <= 1e-12:
                map_x[yy, xx] = INVALID
                map_y[yy, xx] = INVALID
                continue
            x = (pre[0, 0] * xx + pre[0, 1] * yy + pre[0, 2]) / wz
            y = (pre[1, 0] * xx + pre[1, 1] * yy + pre[1, 2]) / wz
            sx = 0.0
            sy = 0.0
            wsum = 0.0
            for i in range(n):
                ex = x - px[i]
                ey = y - py[i]
                u = (ex * dx[i] + ey * dy[i]) / len2[i]
                v = (ex * -dy[i] + ey * dx[i]) / length[i]
                qx = spx[i] + u * sdx[i] + v * -sdy[i] / slen[i]
                qy = spy[i] + u * sdy[i] + v * sdx[i] / slen[i]
                if u < 0.0:
                    dist = np.sqrt(ex * ex + ey * ey)
                elif u > 1.0:
                    fx = x - (px[i] + dx[i])
                    fy = y - (py[i] + dy[i])
                    dist = np.sqrt(fx * fx + fy * fy)
                else:
                    dist = abs(v)
                wt = (lw[i] / (a + dist)) ** b
                sx += wt * (qx - x)
                sy += wt * (qy - y)
                wsum += wt
            if wsum > 0.0:
                x += sx / wsum
                y += sy / wsum
            wq = post[2, 0] * x + post[2, 1] * y + post[2, 2]
            if wq <= 1e-12:
                map_x[yy, xx] = INVALID
                map_y[yy, xx] = INVALID
                continue
            map_x[yy, xx] = (post[0, 0] * x + post[0, 1] * y + post[0, 2]) / wq
            map_y[yy, xx] = (post[1, 0] * x + post[1, 1] * y + post[1, 2]) / wq
