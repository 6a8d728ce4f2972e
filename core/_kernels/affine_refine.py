"""numba kernels of the affine model's refinement (``weft.core.affine.analysis``, Smith & Bhalerao):
the error and the Levenberg-Marquardt normal equations of every patch's affine match, with the gain
of each patch as a seventh unknown. The layout of the arrays is that of
``weft.core._kernels.affine``, which re-exports :func:`lk_systems`.
"""

from __future__ import annotations

from numba import njit


@njit(cache=True, nogil=True, fastmath=True)
def _lk_system(proto, gy, gx, cy, cx, m, oy, ox, g, target, weights, JtJ, Jtr):
    """Error and normal equations of the refinement at (m, oy, ox, g) (sums kept in scalars);
    ``proto``, ``gy``, ``gx`` are padded alike."""
    B = target.shape[0]
    half = (B - 1) * 0.5
    hm = proto.shape[0] - 1.0001
    wm = proto.shape[1] - 1.0001
    e = 0.0
    r0 = 0.0
    r1 = 0.0
    r2 = 0.0
    r3 = 0.0
    r4 = 0.0
    r5 = 0.0
    r6 = 0.0
    s00 = 0.0
    s01 = 0.0
    s02 = 0.0
    s03 = 0.0
    s04 = 0.0
    s05 = 0.0
    s06 = 0.0
    s11 = 0.0
    s12 = 0.0
    s13 = 0.0
    s14 = 0.0
    s15 = 0.0
    s16 = 0.0
    s22 = 0.0
    s23 = 0.0
    s24 = 0.0
    s25 = 0.0
    s26 = 0.0
    s33 = 0.0
    s34 = 0.0
    s35 = 0.0
    s36 = 0.0
    s44 = 0.0
    s45 = 0.0
    s46 = 0.0
    s55 = 0.0
    s56 = 0.0
    s66 = 0.0
    m0 = m[0]
    m1 = m[1]
    m2 = m[2]
    m3 = m[3]
    for a in range(B):
        dy = a - half
        by = cy + m0 * dy + oy
        bx = cx + m2 * dy + ox
        for b in range(B):
            w = weights[a, b]
            if w == 0.0:
                continue
            dx = b - half
            y = min(max(by + m1 * dx, 0.0), hm)
            x = min(max(bx + m3 * dx, 0.0), wm)
            y0 = int(y)
            x0 = int(x)
            ay = y - y0
            ax = x - x0
            w00 = (1.0 - ay) * (1.0 - ax)
            w01 = (1.0 - ay) * ax
            w10 = ay * (1.0 - ax)
            w11 = ay * ax
            v = w00 * proto[y0, x0] + w01 * proto[y0, x0 + 1] + w10 * proto[y0 + 1, x0] + w11 * proto[y0 + 1, x0 + 1]
            vy = w00 * gy[y0, x0] + w01 * gy[y0, x0 + 1] + w10 * gy[y0 + 1, x0] + w11 * gy[y0 + 1, x0 + 1]
            vx = w00 * gx[y0, x0] + w01 * gx[y0, x0 + 1] + w10 * gx[y0 + 1, x0] + w11 * gx[y0 + 1, x0 + 1]
            r = w * (g * v - target[a, b])
            e += r * r
            dvy = w * g * vy
            dvx = w * g * vx
            j0 = dvy * dy
            j1 = dvy * dx
            j2 = dvx * dy
            j3 = dvx * dx
            j4 = dvy
            j5 = dvx
            j6 = w * v
            r0 += j0 * r
            r1 += j1 * r
            r2 += j2 * r
            r3 += j3 * r
            r4 += j4 * r
            r5 += j5 * r
            r6 += j6 * r
            s00 += j0 * j0
            s01 += j0 * j1
            s02 += j0 * j2
            s03 += j0 * j3
            s04 += j0 * j4
            s05 += j0 * j5
            s06 += j0 * j6
            s11 += j1 * j1
            s12 += j1 * j2
            s13 += j1 * j3
            s14 += j1 * j4
            s15 += j1 * j5
            s16 += j1 * j6
            s22 += j2 * j2
            s23 += j2 * j3
            s24 += j2 * j4
            s25 += j2 * j5
            s26 += j2 * j6
            s33 += j3 * j3
            s34 += j3 * j4
            s35 += j3 * j5
            s36 += j3 * j6
            s44 += j4 * j4
            s45 += j4 * j5
            s46 += j4 * j6
            s55 += j5 * j5
            s56 += j5 * j6
            s66 += j6 * j6
    Jtr[0] = r0
    Jtr[1] = r1
    Jtr[2] = r2
    Jtr[3] = r3
    Jtr[4] = r4
    Jtr[5] = r5
    Jtr[6] = r6
    JtJ[0, 0] = s00
    JtJ[0, 1] = s01
    JtJ[1, 0] = s01
    JtJ[0, 2] = s02
    JtJ[2, 0] = s02
    JtJ[0, 3] = s03
    JtJ[3, 0] = s03
    JtJ[0, 4] = s04
    JtJ[4, 0] = s04
    JtJ[0, 5] = s05
    JtJ[5, 0] = s05
    JtJ[0, 6] = s06
    JtJ[6, 0] = s06
    JtJ[1, 1] = s11
    JtJ[1, 2] = s12
    JtJ[2, 1] = s12
    JtJ[1, 3] = s13
    JtJ[3, 1] = s13
    JtJ[1, 4] = s14
    JtJ[4, 1] = s14
    JtJ[1, 5] = s15
    JtJ[5, 1] = s15
    JtJ[1, 6] = s16
    JtJ[6, 1] = s16
    JtJ[2, 2] = s22
    JtJ[2, 3] = s23
    JtJ[3, 2] = s23
    JtJ[2, 4] = s24
    JtJ[4, 2] = s24
    JtJ[2, 5] = s25
    JtJ[5, 2] = s25
    JtJ[2, 6] = s26
    JtJ[6, 2] = s26
    JtJ[3, 3] = s33
    JtJ[3, 4] = s34
    JtJ[4, 3] = s34
    JtJ[3, 5] = s35
    JtJ[5, 3] = s35
    JtJ[3, 6] = s36
    JtJ[6, 3] = s36
    JtJ[4, 4] = s44
    JtJ[4, 5] = s45
    JtJ[5, 4] = s45
    JtJ[4, 6] = s46
    JtJ[6, 4] = s46
    JtJ[5, 5] = s55
    JtJ[5, 6] = s56
    JtJ[6, 5] = s56
    JtJ[6, 6] = s66
    return e


@njit(cache=True, nogil=True, fastmath=True)
def lk_systems(proto, gy, gx, cy, cx, params, targets, weights, JtJ, Jtr, err):
    """The refinement's error and normal equations for every patch i at ``params[i]`` =
    (M00, M01, M10, M11, offset y, offset x, gain): the residual is
    ``w (g P(c + M y + o) - s_t)`` over the patch (an addition to the paper, see
    ``weft.core.affine.analysis``); the Levenberg-Marquardt steps are taken by the caller."""
    for i in range(params.shape[0]):
        err[i] = _lk_system(
            proto,
            gy,
            gx,
            cy,
            cx,
            params[i],
            params[i, 4],
            params[i, 5],
            params[i, 6],
            targets[i],
            weights[i],
            JtJ[i],
            Jtr[i],
        )
