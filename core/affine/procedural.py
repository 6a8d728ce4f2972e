"""Procedural test textures of the kind the affine model is for (Smith & Bhalerao §5).

The paper measures its synthesis on a reptile skin (cells about one patch in size) and on burlap,
"perfect examples of the class of textures best suited": clear repetition and a subtle change of
orientation across the image. These generators make such textures with known structure, for tests
and benchmarks:

* :func:`cells` -- reptile-like scales: Voronoi cells of a jittered hexagonal lattice, domed and
  lit from the top left, with dark grooves and a tone per cell;
* :func:`weave` -- a plain (burlap-like) or basket weave: threads crossing over and under, with
  fibres.

Both are drawn in texture coordinates ``q = f(z)`` of a conformal map of the image plane,
``f(z) = (W/β)(exp(β z/W) - 1)`` with ``β = i·drift``: conformal maps are locally a rotation and a
scale without shear, so the texture's orientation drifts smoothly across the image (``drift``
radians from left to right) and its scale by a factor ``exp(drift)`` from top to bottom, and
every small patch is an affine (similarity) image of every other -- the model of §2.
"""

from __future__ import annotations

import cv2
import numpy as np


def _size(size) -> tuple[int, int]:
    if isinstance(size, (int, np.integer)):
        return int(size), int(size)
    w, h = size
    return int(w), int(h)


def drift_coordinates(size, drift: float) -> tuple[np.ndarray, np.ndarray]:
    """Texture coordinates ``(qy, qx)`` (pixels) of every pixel under the conformal drift map.

    Parameters
    ----------
    size : int or (width, height)
    drift : float
        β: the orientation turns by ``drift`` radians from the left edge to the right edge and the
        scale changes by ``exp(drift)`` from the top to the bottom; 0 is the identity.
    """
    w, h = _size(size)
    y, x = np.mgrid[:h, :w].astype(np.float64)
    z = (x - (w - 1) / 2) + 1j * (y - (h - 1) / 2)
    if drift == 0:
        q = z
    else:
        beta = 1j * drift
        q = (w / beta) * (np.exp(beta * z / w) - 1.0)
    return q.imag, q.real


def _hash(i: np.ndarray, j: np.ndarray, seed: int, salt: int) -> np.ndarray:
    """Deterministic uniform [0, 1) per integer lattice site."""
    v = (i.astype(np.int64) * 73856093) ^ (j.astype(np.int64) * 19349663) ^ ((seed * 83492791 + salt * 2654435761) & 0x7FFFFFFF)
    v = (v ^ (v >> 13)) * 1274126177
    v = v ^ (v >> 16)
    return (v & 0xFFFFFF).astype(np.float64) / float(0x1000000)


def cells(size=512, *, spacing: float = 16.0, drift: float = 0.4, jitter: float = 0.02, tone: float = 0.04,
          blur: float = 0.7, seed: int = 0) -> np.ndarray:
    """Reptile-like scales: Voronoi cells of a jittered hexagonal lattice with a drifting frame.

    Parameters
    ----------
    size : int or (width, height), default 512
    spacing : float, default 16
        Distance between neighbouring cell centres, pixels (at the image's centre).
    drift : float, default 0.4
        Orientation / scale drift across the image (see :func:`drift_coordinates`).
    jitter : float, default 0.02
        Random displacement of the cell centres, as a fraction of the spacing.
    tone : float, default 0.04
        Random brightness variation from cell to cell (fraction).
    blur : float, default 0.7
        Gaussian blur σ in pixels, as a camera's optics would give (0: none).
    seed : int
        Same seed, same image.

    Returns
    -------
    float32 (H, W) in [0, 1]
    """
    qy, qx = drift_coordinates(size, drift)
    u = qx / spacing
    v = qy / spacing
    s3 = np.sqrt(3.0) / 2.0
    j0 = np.floor(v / s3)
    i0 = np.floor(u - 0.5 * j0)
    d1 = np.full(u.shape, np.inf)
    d2 = np.full(u.shape, np.inf)
    vy = np.zeros(u.shape)
    vx = np.zeros(u.shape)
    tone_of = np.zeros(u.shape)
    for dj in (-1, 0, 1, 2):
        for di in (-1, 0, 1, 2):
            i = i0 + di
            j = j0 + dj
            cx = i + 0.5 * j + jitter * (_hash(i, j, seed, 1) - 0.5) * 2
            cy = j * s3 + jitter * (_hash(i, j, seed, 2) - 0.5) * 2
            ey = v - cy
            ex = u - cx
            d = np.hypot(ey, ex)
            nearer = d < d1
            d2 = np.where(nearer, d1, np.minimum(d2, d))
            d1 = np.where(nearer, d, d1)
            vy = np.where(nearer, ey, vy)
            vx = np.where(nearer, ex, vx)
            tone_of = np.where(nearer, _hash(i, j, seed, 3), tone_of)
    groove = np.clip((d2 - d1) / 0.22, 0.0, 1.0) ** 0.7
    r = np.clip(d1 / 0.62, 0.0, 1.0)
    dome = np.sqrt(1.0 - r ** 2)
    light = np.clip(0.55 - 0.9 * (0.6 * vy + 0.8 * vx) * (1.0 - 0.3 * r), 0.0, 1.2)  # lit from the top left
    value = 0.12 + 0.72 * groove * (0.35 + 0.45 * dome * light + 0.2 * dome) * (1.0 - tone * tone_of)
    return _finish(value, blur, seed)


def weave(size=512, *, thread: float = 9.0, group: int = 2, drift: float = 0.25, blur: float = 0.7,
          seed: int = 0) -> np.ndarray:
    """A woven texture: groups of threads alternately horizontal and vertical, with fibres.

    Parameters
    ----------
    size : int or (width, height), default 512
    thread : float, default 9
        Thread width, pixels.
    group : int, default 2
        Threads per group: 1 is a plain weave (burlap: every thread goes over one and under the
        next; the pattern repeats every two threads), 2 a basket weave (pairs; every four).
    drift : float, default 0.25
        Orientation / scale drift across the image (see :func:`drift_coordinates`).
    blur : float, default 0.7
        Gaussian blur σ in pixels, as a camera's optics would give (0: none).
    seed : int
        Same seed, same image (thread tones and the faint noise).

    Returns
    -------
    float32 (H, W) in [0, 1]
    """
    qy, qx = drift_coordinates(size, drift)
    u = qx / thread
    v = qy / thread
    if group < 1:
        raise ValueError(f"group = {group} must be at least 1")
    bi = np.floor(u / group)
    bj = np.floor(v / group)
    horizontal = (bi + bj) % 2 == 0
    # across: position across the visible thread (0..1); along: position along it within its block
    across = np.where(horizontal, v - np.floor(v), u - np.floor(u))
    along = np.where(horizontal, (u / group) - bi, (v / group) - bj)
    lane = np.where(horizontal, np.floor(v), np.floor(u))
    profile = np.sin(np.pi * np.clip(across, 0.0, 1.0)) ** 0.8  # round thread, dark gaps between
    dip = np.sin(np.pi * np.clip(along, 0.0, 1.0)) ** 0.35  # the thread dives under at the block ends
    fibre_phase = np.where(horizontal, u * 1.7 + 0.35 * v, v * 1.7 + 0.35 * u)
    fibres = 0.06 * np.sin(2 * np.pi * fibre_phase)
    tone = 0.9 + 0.1 * _hash(lane, np.where(horizontal, bi, bj), seed, 5)
    value = 0.1 + 0.75 * profile * (0.45 + 0.55 * dip) * tone + fibres * profile
    shade = np.where(horizontal, 0.0, -0.05)  # the vertical pairs sit a little deeper
    value = value + shade
    return _finish(value, blur, seed)


def _finish(value: np.ndarray, blur: float, seed: int) -> np.ndarray:
    """Camera-like blur, faint sensor noise (σ = 0.008), clipped to [0, 1], float32."""
    img = value.astype(np.float32)
    if blur > 0:
        img = cv2.GaussianBlur(img, (0, 0), blur, borderType=cv2.BORDER_REFLECT)
    rng = np.random.default_rng(seed)
    img = img + rng.normal(0.0, 0.008, img.shape).astype(np.float32)
    return np.clip(img, 0.0, 1.0).astype(np.float32)
