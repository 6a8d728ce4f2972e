"""The cases of the public fill suite (``python -m benchmarks.fill_suite``), built in code.

Every case is a crop of a picture the project may ship or install (scikit-image's data images, the
bundled examples in ``resources/``, the procedural textures of :mod:`benchmarks.fixtures`) with a
hole cut from it, so the truth is known. A case names its picture, its crop and its hole; the
hole's random shape comes from a generator seeded by the case's name, so a case is the same on
every machine and adding a case changes no other.

The suite is split once, by name, into a *tuning* half and a *check* half (:func:`half`): the
parity of the first byte of the name's SHA-1. Constants are chosen on the tuning half and reported
on the check half.
"""

from __future__ import annotations

import hashlib
from collections.abc import Callable
from dataclasses import dataclass
from functools import cache
from pathlib import Path

import cv2
import numpy as np

RESOURCES = Path(__file__).resolve().parent.parent / "resources"


@dataclass(frozen=True)
class SuiteInputs:
    """A built case. ``truth`` (uint8, the whole canvas); ``hole`` (bool, its unknown pixels);
    ``image`` (uint8, what the peers get: the truth with the hole set to 0); ``extend`` (L, T, R, B)
    for an uncrop, when weft gets only the known centre and grows the canvas itself; ``alpha``: weft
    gets an RGBA picture whose transparent pixels are the hole, and no mask."""

    truth: np.ndarray
    hole: np.ndarray
    image: np.ndarray
    extend: tuple[int, int, int, int] | None = None
    alpha: bool = False

    def part(self, arr: np.ndarray) -> np.ndarray:
        """``arr`` (canvas-sized) cut to what weft is given: the canvas less an uncrop's margins."""
        if self.extend is None:
            return arr
        left, top, right, bottom = self.extend
        h, w = arr.shape[:2]
        return arr[top : h - bottom, left : w - right]


@dataclass(frozen=True)
class SuiteCase:
    name: str
    build: Callable[[], SuiteInputs]
    note: str

    @property
    def half(self) -> str:
        return half(self.name)


def half(name: str) -> str:
    """``"tuning"`` or ``"check"``: the once-and-for-all split of the suite by case name."""
    return "tuning" if hashlib.sha1(name.encode()).digest()[0] % 2 == 0 else "check"


def _rng(name: str) -> np.random.Generator:
    return np.random.default_rng(int.from_bytes(hashlib.sha1(name.encode()).digest()[:8], "little"))


# ------------------------------------------------------------------------------------------- pictures


@cache
def _skimage(name: str) -> np.ndarray:
    from skimage import data

    return np.asarray(getattr(data, name)())


@cache
def _resource(name: str) -> np.ndarray:
    from PIL import Image

    with Image.open(RESOURCES / name) as im:
        return np.asarray(im.convert("RGB" if im.mode in ("RGB", "RGBA", "P") else "L"))


@cache
def _procedural(name: str) -> np.ndarray:
    from .fixtures import procedural

    img = getattr(procedural, name)(256, seed=3)
    return np.clip(np.rint(np.asarray(img) * 255), 0, 255).astype(np.uint8)


def _picture(source: str) -> np.ndarray:
    kind, name = source.split(":")
    if kind == "sk":
        img = _skimage(name)
        if name == "retina":  # 1411 px: brought down to the size of the others
            img = cv2.resize(img, (352, 352), interpolation=cv2.INTER_AREA)
        if name == "hubble_deep_field":
            img = cv2.resize(img, (500, 436), interpolation=cv2.INTER_AREA)
        return img
    if kind == "res":
        return _resource(name)
    return _procedural(name)


# ---------------------------------------------------------------------------------------------- holes


def blob(shape, rng, cx, cy, r) -> np.ndarray:
    """A smooth blob of mean radius ``r`` around (cx, cy): a radius that wobbles with the angle."""
    t = np.linspace(0, 2 * np.pi, 96, endpoint=False)
    a1, a2, p1, p2 = rng.uniform(0.1, 0.3), rng.uniform(0.05, 0.15), rng.uniform(0, 6.3), rng.uniform(0, 6.3)
    rr = r * (1 + a1 * np.sin(2 * t + p1) + a2 * np.sin(3 * t + p2))
    pts = np.stack([cx + rr * np.cos(t), cy + rr * np.sin(t)], axis=1)
    m = np.zeros(shape, np.uint8)
    cv2.fillPoly(m, [np.rint(pts).astype(np.int32)], 1)
    return m.astype(bool)


def stroke(shape, rng, points, width=8) -> np.ndarray:
    """A wire: a polyline ``width`` px thick through ``points``, each inner point moved up to 6 px."""
    pts = np.array(points, np.float64)
    pts[1:-1] += rng.uniform(-6, 6, pts[1:-1].shape)
    m = np.zeros(shape, np.uint8)
    cv2.polylines(m, [np.rint(pts).astype(np.int32)], False, 1, thickness=width, lineType=cv2.LINE_8)
    return m.astype(bool)


def rect(shape, x, y, w, h) -> np.ndarray:
    m = np.zeros(shape, bool)
    m[y : y + h, x : x + w] = True
    return m


def several(shape, rng, centres, r) -> np.ndarray:
    m = np.zeros(shape, bool)
    for cx, cy in centres:
        m |= blob(shape, rng, cx, cy, r * rng.uniform(0.8, 1.2))
    return m


def _case(name, source, crop, hole, note, *, extend=None, alpha=False) -> SuiteCase:
    """A case: picture ``source`` ("sk:NAME", "res:FILE", "proc:NAME"), ``crop`` (y0, y1, x0, x1) of
    it (the truth), ``hole(shape, rng)`` -> bool (the interior hole, or None), ``extend`` the
    margins of the truth that weft must grow back."""

    def build() -> SuiteInputs:
        y0, y1, x0, x1 = crop
        truth = np.ascontiguousarray(_picture(source)[y0:y1, x0:x1])
        shape = truth.shape[:2]
        m = np.zeros(shape, bool) if hole is None else hole(shape, _rng(name))
        if extend is not None:
            left, top, right, bottom = extend
            border = np.ones(shape, bool)
            border[top : shape[0] - bottom, left : shape[1] - right] = False
            m = m | border
        image = truth.copy()
        image[m] = 0
        return SuiteInputs(truth, m, image, extend, alpha)

    return SuiteCase(name, build, note)


def _spoon_case(name: str, right: int) -> SuiteCase:
    """coffee()'s spoon pasted over the saucer's rim and the wood (its silhouette grown by 4 px is the
    hole: a loose lasso), optionally with ``right`` px of the truth's right side to grow back."""

    def build() -> SuiteInputs:
        from .fill import build_object

        obj = build_object()
        photo = _skimage("coffee")
        truth = np.ascontiguousarray(photo[80:400, 0 : 320 + right])
        hole = np.zeros(truth.shape[:2], bool)
        hole[:, :320] = obj.hole
        image = truth.copy()
        image[:, :320] = obj.image
        if right:
            hole[:, 320:] = True
        image[hole] = 0
        return SuiteInputs(truth, hole, image, (0, 0, right, 0) if right else None)

    note = "coffee's spoon pasted over the saucer's rim and the wood, lassoed" + (
        f"; and the right {right} px grown back (an uncrop beside an interior hole)" if right else ""
    )
    return SuiteCase(name, build, note)


def _cat_eye(name: str) -> SuiteCase:
    """chelsea's left eye and nose under a transparent 110x100 rectangle (an RGBA picture, no mask)."""
    return _case(
        name,
        "sk:chelsea",
        (40, 300, 100, 400),
        lambda s, r: rect(s, 135, 95, 110, 100),
        "chelsea (cat face), RGBA: a transparent 110x100 rectangle over an eye and the nose, no mask",
        alpha=True,
    )


S = 256  # the side of most crops


def _cases() -> list[SuiteCase]:
    b = blob
    return [
        # grey, stochastic / regular / directional / fine textures
        _case(
            "gravel-blob",
            "sk:gravel",
            (96, 352, 96, 352),
            lambda s, r: b(s, r, 128, 120, 34),
            "gravel, grey stochastic: a blob",
        ),
        _case(
            "gravel-stroke",
            "sk:gravel",
            (200, 456, 40, 296),
            lambda s, r: stroke(s, r, [(10, 200), (120, 150), (246, 180)], 10),
            "gravel: a 10-px wire",
        ),
        _case(
            "gravel-large",
            "sk:gravel",
            (0, 256, 256, 512),
            lambda s, r: rect(s, 70, 60, 120, 120),
            "gravel: a large hole (22 %)",
        ),
        _case(
            "gravel-uncrop-right",
            "sk:gravel",
            (256, 512, 0, 256),
            None,
            "gravel: uncrop, right 64 px",
            extend=(0, 0, 64, 0),
        ),
        _case(
            "brick-rect",
            "sk:brick",
            (64, 320, 64, 320),
            lambda s, r: rect(s, 80, 100, 96, 40),
            "brick, grey regular: a 96x40 box across a mortar course",
        ),
        _case(
            "brick-several",
            "sk:brick",
            (256, 512, 256, 512),
            lambda s, r: several(s, r, [(60, 60), (190, 90), (120, 200)], 16),
            "brick: three holes",
        ),
        _case(
            "brick-border",
            "sk:brick",
            (0, 256, 200, 456),
            lambda s, r: b(s, r, 256, 130, 40),
            "brick: a blob on the right border",
        ),
        _case(
            "brick-uncrop-all",
            "sk:brick",
            (128, 448, 128, 448),
            None,
            "brick: uncrop all around, 40 px",
            extend=(40, 40, 40, 40),
        ),
        _case(
            "grass-blob",
            "sk:grass",
            (0, 256, 0, 256),
            lambda s, r: b(s, r, 140, 110, 30),
            "grass, grey fine detail: a blob",
        ),
        _case(
            "grass-stroke",
            "sk:grass",
            (256, 512, 128, 384),
            lambda s, r: stroke(s, r, [(30, 20), (110, 140), (220, 236)], 8),
            "grass: an 8-px wire",
        ),
        _case(
            "grass-uncrop-two",
            "sk:grass",
            (200, 456, 200, 456),
            None,
            "grass: uncrop right and bottom 48 px",
            extend=(0, 0, 48, 48),
        ),
        _case(
            "hatching-rect",
            "res:hatching.png",
            (0, 256, 0, 256),
            lambda s, r: rect(s, 90, 80, 70, 60),
            "hatching.png, grey directional: a 70x60 box",
        ),
        _case(
            "hatching-uncrop-right",
            "res:hatching.png",
            (0, 256, 0, 256),
            None,
            "hatching: uncrop, right 64 px",
            extend=(0, 0, 64, 0),
        ),
        _case(
            "clouds-blob",
            "res:clouds.png",
            (0, 256, 0, 256),
            lambda s, r: b(s, r, 120, 130, 36),
            "clouds.png, grey smooth: a blob",
        ),
        _case(
            "text-stroke",
            "sk:text",
            (0, 172, 60, 316),
            lambda s, r: stroke(s, r, [(0, 90), (128, 70), (255, 100)], 8),
            "text, grey structure: a wire across the letters",
        ),
        _case(
            "page-rect",
            "sk:page",
            (0, 191, 0, 256),
            lambda s, r: rect(s, 100, 70, 60, 40),
            "page, grey text lines: a box",
        ),
        # grey photos
        _case(
            "camera-lawn-blob",
            "sk:camera",
            (256, 512, 256, 512),
            lambda s, r: b(s, r, 120, 110, 28),
            "camera: lawn beside the tripod's leg, a blob",
        ),
        _case(
            "camera-sky-blob",
            "sk:camera",
            (0, 256, 256, 512),
            lambda s, r: b(s, r, 150, 60, 30),
            "camera: sky over the buildings, smooth gradient, a blob",
        ),
        _case(
            "camera-coat-stroke",
            "sk:camera",
            (100, 356, 100, 356),
            lambda s, r: stroke(s, r, [(0, 200), (128, 130), (255, 40)], 8),
            "camera: a wire across the coat, hand and camera",
        ),
        _case(
            "camera-large",
            "sk:camera",
            (256, 512, 0, 256),
            lambda s, r: b(s, r, 170, 140, 66),
            "camera: a large blob over the coat's edge and lawn (20 %)",
        ),
        _case(
            "coins-blob",
            "sk:coins",
            (20, 276, 0, 256),
            lambda s, r: b(s, r, 110, 140, 24),
            "coins, objects on a background: a blob on a coin's rim",
        ),
        _case(
            "moon-several",
            "sk:moon",
            (128, 384, 128, 384),
            lambda s, r: several(s, r, [(70, 70), (180, 100), (100, 190)], 14),
            "moon, grey smooth: three holes",
        ),
        _case(
            "clock-rect",
            "sk:clock",
            (20, 276, 100, 356),
            lambda s, r: rect(s, 100, 100, 50, 40),
            "clock: a box over the face's edges",
        ),
        _case(
            "cells-blob",
            "proc:cells",
            (0, 256, 0, 256),
            lambda s, r: b(s, r, 128, 128, 32),
            "procedural scales (regular, drifting): a blob",
        ),
        _case(
            "cells-uncrop-right",
            "proc:cells",
            (0, 256, 0, 256),
            None,
            "procedural scales: uncrop, right 64 px",
            extend=(0, 0, 64, 0),
        ),
        _case(
            "weave-rect",
            "proc:weave",
            (0, 256, 0, 256),
            lambda s, r: rect(s, 80, 100, 80, 50),
            "procedural weave (fabric): a box",
        ),
        _case(
            "weave-stroke",
            "proc:weave",
            (0, 256, 0, 256),
            lambda s, r: stroke(s, r, [(20, 20), (128, 110), (236, 236)], 8),
            "procedural weave: a wire",
        ),
        # colour photos
        _spoon_case("coffee-spoon", 0),
        _spoon_case("coffee-spoon-uncrop", 64),
        _case(
            "coffee-rim-blob",
            "sk:coffee",
            (100, 356, 0, 256),
            lambda s, r: b(s, r, 96, 150, 26),
            "coffee: a blob on the saucer's rim over the wood",
        ),
        _case(
            "coffee-large",
            "sk:coffee",
            (144, 400, 344, 600),
            lambda s, r: b(s, r, 110, 130, 64),
            "coffee: a large blob over the saucer's right side and wood (20 %)",
        ),
        _case(
            "coffee-uncrop-two",
            "sk:coffee",
            (0, 256, 0, 256),
            None,
            "coffee: uncrop left and top 48 px",
            extend=(48, 48, 0, 0),
        ),
        _case(
            "astronaut-face-blob",
            "sk:astronaut",
            (40, 296, 100, 356),
            lambda s, r: b(s, r, 122, 100, 22),
            "astronaut: skin of the face (a cheek), a blob",
        ),
        _case(
            "astronaut-flag-rect",
            "sk:astronaut",
            (100, 356, 0, 256),
            lambda s, r: rect(s, 10, 120, 60, 50),
            "astronaut: the flag's stripes, a box",
        ),
        _case(
            "astronaut-suit-stroke",
            "sk:astronaut",
            (256, 512, 0, 256),
            lambda s, r: stroke(s, r, [(0, 60), (120, 120), (255, 90)], 8),
            "astronaut: a wire across the suit and its badge",
        ),
        _case(
            "astronaut-border",
            "sk:astronaut",
            (0, 256, 256, 512),
            lambda s, r: b(s, r, 256, 90, 36),
            "astronaut: a blob on the right border, over the shuttle model",
        ),
        _case(
            "astronaut-uncrop-all",
            "sk:astronaut",
            (0, 288, 0, 288),
            None,
            "astronaut: uncrop all around, 32 px",
            extend=(32, 32, 32, 32),
        ),
        _cat_eye("chelsea-eye-alpha"),
        _case(
            "chelsea-fur-blob",
            "sk:chelsea",
            (0, 256, 0, 256),
            lambda s, r: b(s, r, 80, 190, 28),
            "chelsea: the fur of a cheek, a blob",
        ),
        _case(
            "chelsea-several",
            "sk:chelsea",
            (44, 300, 195, 451),
            lambda s, r: several(s, r, [(50, 60), (140, 180), (210, 90)], 14),
            "chelsea: three holes on the face and background",
        ),
        _case(
            "chelsea-uncrop-right",
            "sk:chelsea",
            (0, 256, 100, 356),
            None,
            "chelsea: uncrop, right 64 px",
            extend=(0, 0, 64, 0),
        ),
        _case(
            "rocket-sky-blob",
            "sk:rocket",
            (0, 256, 150, 406),
            lambda s, r: b(s, r, 100, 110, 32),
            "rocket: the evening sky, smooth gradient, a blob",
        ),
        _case(
            "rocket-tower-rect",
            "sk:rocket",
            (150, 406, 384, 640),
            lambda s, r: rect(s, 180, 60, 50, 80),
            "rocket: the launch tower's lattice, fine repeated detail, a box",
        ),
        _case(
            "rocket-stroke",
            "sk:rocket",
            (0, 256, 256, 512),
            lambda s, r: stroke(s, r, [(0, 150), (128, 120), (255, 160)], 8),
            "rocket: a wire across the sky and the rocket",
        ),
        _case(
            "rocket-uncrop-two",
            "sk:rocket",
            (100, 356, 200, 456),
            None,
            "rocket: uncrop top and right 48 px",
            extend=(0, 48, 48, 0),
        ),
        _case(
            "ihc-blob",
            "sk:immunohistochemistry",
            (0, 256, 0, 256),
            lambda s, r: b(s, r, 128, 128, 30),
            "immunohistochemistry, colour stochastic: a blob",
        ),
        _case(
            "ihc-large",
            "sk:immunohistochemistry",
            (256, 512, 256, 512),
            lambda s, r: rect(s, 60, 70, 130, 110),
            "immunohistochemistry: a large box (22 %)",
        ),
        _case(
            "woodgrain-stroke",
            "res:wood-grain.png",
            (0, 128, 0, 112),
            lambda s, r: stroke(s, r, [(0, 40), (56, 70), (111, 90)], 6),
            "wood-grain.png, colour directional: a 6-px wire",
        ),
        _case(
            "woodgrain-uncrop-right",
            "res:wood-grain.png",
            (0, 128, 0, 112),
            None,
            "wood-grain: uncrop, right 24 px",
            extend=(0, 0, 24, 0),
        ),
        _case(
            "frontal-rect",
            "res:perspective-frontal.png",
            (0, 256, 0, 256),
            lambda s, r: rect(s, 90, 100, 70, 50),
            "perspective-frontal.png (bricks and sky, colour): a box",
        ),
        _case(
            "hubble-several",
            "sk:hubble_deep_field",
            (0, 256, 0, 256),
            lambda s, r: several(s, r, [(60, 70), (180, 60), (130, 190)], 13),
            "hubble deep field (galaxies on black): three holes",
        ),
        _case(
            "retina-blob",
            "sk:retina",
            (48, 304, 48, 304),
            lambda s, r: b(s, r, 150, 120, 26),
            "retina: a blob on the vessels",
        ),
    ]


CASES: list[SuiteCase] = _cases()


def by_name() -> dict[str, SuiteCase]:
    return {c.name: c for c in CASES}
