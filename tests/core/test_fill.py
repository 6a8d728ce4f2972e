"""weft.core.fill: the engines (known pixels untouched, seeds deterministic, quality bounds from
weft.core.metrics on small cases), the blend band, alpha, uncrop geometry and the Python API."""

import cv2
import numpy as np
import pytest
from weft.core import metrics
from weft.core.errors import InvalidParameter, WeftError
from weft.core.examples import example
from weft.core.fill import ENGINES, FillParams, fill, fill_quilt
from weft.core.fill.band import band_region, blend_band
from weft.core.fill.hybrid import fill_hybrid
from weft.core.image import load_image

from .fill_cases import brick, gravel, square_hole  # noqa: F401 (fixtures)

ENGINE_FUNCS = {"quilt": fill_quilt, "hybrid": fill_hybrid}


@pytest.mark.parametrize("engine", sorted(ENGINE_FUNCS))
def test_engine_leaves_known_pixels_and_is_deterministic(engine, gravel):
    hole = square_hole(gravel.shape)
    garbage = gravel.copy()
    garbage[hole] = 1.0  # values in the hole are ignored
    f = ENGINE_FUNCS[engine]
    a = f(garbage, hole, patch=9 if engine == "quilt" else 5, rng=3)
    b = f(gravel, hole, patch=9 if engine == "quilt" else 5, rng=3)
    c = f(gravel, hole, patch=9 if engine == "quilt" else 5, rng=4)
    assert a.dtype == np.float32 and a.shape == gravel.shape
    assert np.array_equal(a[~hole], gravel[~hole])
    assert np.array_equal(a, b)  # same seed, same pixels; the hole's old values play no part
    assert not np.array_equal(a[hole], c[hole])
    assert not np.any(a[hole] == 1.0) or np.mean(a[hole] == 1.0) < 0.01


@pytest.mark.parametrize("engine", sorted(ENGINE_FUNCS))
@pytest.mark.parametrize("case", ["gravel", "brick"])
def test_engine_quality_bounds(engine, case, gravel, brick):
    """On a 96x96 crop with a 36x28 hole: coherence no worse than 1.5x the ground truth's (the
    truth itself is far from the nearest known patch), detail within 0.6..1.4 of the truth's,
    seam within 0.5 of the truth's after the blend band."""
    img = gravel if case == "gravel" else brick
    hole = square_hole(img.shape)
    out = fill(img, hole, engine=engine, seed=1)
    truth_coh = metrics.fill_coherence(img, hole)
    assert metrics.fill_coherence(out, hole) <= 1.5 * truth_coh
    truth_detail = metrics.fill_detail(img, hole)
    assert 0.6 * truth_detail <= metrics.fill_detail(out, hole) <= 1.4 * truth_detail
    assert abs(metrics.fill_seam(out, hole) - metrics.fill_seam(img, hole)) <= 0.5


def test_a_smear_fails_the_detail_bound(gravel):
    """The bounds above can fail: a diffusion fill is far below them."""
    import cv2

    hole = square_hole(gravel.shape)
    smeared = cv2.inpaint((gravel * 255).astype(np.uint8), hole.astype(np.uint8), 3, cv2.INPAINT_TELEA) / 255.0
    assert metrics.fill_detail(smeared.astype(np.float32), hole) < 0.6 * metrics.fill_detail(gravel, hole)


def test_engine_copies_only_from_the_source(brick):
    hole = square_hole(brick.shape)
    source = np.zeros(brick.shape, dtype=bool)
    source[64:, :] = True  # only the bottom rows
    marked = brick.copy()
    marked[:64] = 0.0  # nothing black exists below row 64 in the brick crop
    assert marked[64:].min() > 0.0
    out = fill_quilt(marked, hole, source, patch=12, rng=0)
    assert out[hole].min() > 0.0  # no pixel came from the blackened, non-source rows
    out = fill_hybrid(marked, hole, source, patch=12, rng=0)
    assert out[hole].min() > 0.0


def test_engine_refuses_a_source_without_a_whole_patch(gravel):
    hole = np.ones(gravel.shape, dtype=bool)
    hole[:, :5] = False  # a 5-pixel strip: no 9x9 patch
    with pytest.raises(WeftError, match="needs at least one whole 9x9 patch"):
        fill_quilt(gravel, hole, patch=9)


def test_band_changes_only_pixels_within_band(brick):
    hole = square_hole(brick.shape)
    raw = fill(brick, hole, band=0, seed=2)
    assert np.array_equal(raw[~hole], brick[~hole])  # band 0: no known pixel changes
    blended = fill(brick, hole, band=3, seed=2)
    ring = band_region(hole, 3)
    outside = ~hole & ~ring
    assert np.array_equal(blended[outside], brick[outside])  # beyond the band, bit-identical
    assert not np.array_equal(blended[ring & ~hole], brick[ring & ~hole])  # within it, known pixels blend
    # the ring is exactly the pixels within 3 px (8-connected) of the hole's edge, on both sides
    assert ring[29, 40] and ring[34, 40] and not ring[28, 40] and not ring[35, 40]  # hole rows 32..59


def test_band_spreads_a_step_at_the_seam():
    img = np.zeros((32, 32, 1), dtype=np.float32)
    hole = np.zeros((32, 32), dtype=bool)
    hole[:, 16:] = True
    img[:, 16:] = 0.5  # a step of 0.5 exactly at the hole's edge
    out = blend_band(img, hole, 4)[..., 0]
    assert np.abs(np.diff(out[10])).max() < 0.2  # spread over the band (0.5 / 8 px ~ 0.07 a step)
    assert np.array_equal(out[:, :12], img[:, :12, 0]) and np.array_equal(out[:, 20:], img[:, 20:, 0])


def test_band_spreads_the_step_where_the_cut_left_it():
    """The quilting cut may run through the band's known pixels: the seam is then where written meets
    unwritten pixels, inside the band, not the hole's edge. Given ``written``, the step there is
    spread too; without it, it was kept as the image's own gradient (a line along an uncrop's edge)."""
    rng = np.random.default_rng(0)
    img = (0.5 + 0.01 * rng.standard_normal((32, 32, 1))).astype(np.float32)
    hole = np.zeros((32, 32), dtype=bool)
    hole[:, 16:] = True
    written = hole.copy()
    written[:, 13:16] = True  # the cut ran 3 px into the band
    img[written] += 0.2  # the block's level: a step of 0.2 between columns 12 and 13
    jump = lambda out: float(np.abs(out[:, 13, 0] - out[:, 12, 0]).mean())  # noqa: E731
    assert jump(blend_band(img, hole, 4)) > 0.15  # the hole's edge alone: the step stays
    out = blend_band(img, hole, 4, written=written)
    assert jump(out) < 0.1
    keep = ~band_region(hole, 4)
    assert np.array_equal(out[keep], img[keep])


def test_alpha_hole_and_opaque_output(gravel):
    rgba = np.dstack([np.repeat(gravel[..., None], 3, axis=2), np.ones(gravel.shape, np.float32)])
    hole = square_hole(gravel.shape)
    rgba[hole, 3] = 0.0
    rgba[hole, :3] = 1.0
    out = fill(rgba, seed=0)
    assert out.shape == rgba.shape
    assert np.all(out[..., 3] == 1.0)
    ring = band_region(hole, 2)
    assert np.array_equal(out[~hole & ~ring], rgba[~hole & ~ring])
    assert out[hole, :3].mean() < 0.9  # filled with gravel, not the transparent pixels' white


def test_extend_and_size_grow_the_canvas(gravel):
    out = fill(gravel, extend=(8, 0, 16, 4), seed=0)
    assert out.shape == (100, 120)
    assert np.array_equal(out[:94, 10:102], gravel[:94, 2:94])  # the image, away from the band, is intact
    anchored = fill(gravel, size=(128, 112), anchor="bottom-right", seed=0)
    assert anchored.shape == (112, 128)
    assert np.array_equal(anchored[18:, 34:], gravel[2:, 2:])
    top_left = fill(gravel, size=(128, 112), anchor="top-left", seed=0, band=0)
    assert np.array_equal(top_left[:96, :96], gravel)


def test_texture_is_the_source(gravel, brick):
    hole = square_hole(gravel.shape)
    out = fill(gravel, hole, texture=np.full((64, 64), 0.25, np.float32) + 0 * brick[:64, :64], seed=0, band=0)
    assert np.allclose(out[hole], 0.25)
    assert np.array_equal(out[~hole], gravel[~hole])


@pytest.mark.parametrize("engine", ENGINES)
def test_texture_fill_keeps_the_images_pixels_beyond_the_band(engine, gravel, brick):
    """The texture sits below the image on the engine's canvas with a gap between them; the band
    is the image's own, not one that reaches into the image's last rows from that gap (review)."""
    hole = square_hole(gravel.shape)
    out = fill(gravel, hole, texture=brick[:80, :80], seed=1, engine=engine, band=2)
    beyond = ~band_region(hole, 2) & ~hole
    assert np.array_equal(out[beyond], gravel[beyond])


def test_onion_order_is_the_same_on_every_call():
    from weft.core.fill.common import onion_order

    rng = np.random.default_rng(3)
    hole = rng.random((40, 40)) < 0.3
    first = onion_order(hole)
    for _ in range(20):  # OpenCV's precise distance transform varied in its last bit between calls
        assert np.array_equal(onion_order(hole), first)


def test_a_recipe_of_the_dropped_pixel_engine_still_runs(gravel):
    """``pixel`` was dropped (the hybrid measured better on every suite case it was run on); a recipe
    that names it runs the default engine, and the command line refuses it in one line."""
    from weft.core.errors import InvalidParameter

    params = FillParams.from_dict({"engine": "pixel", "patch": 5})
    assert params.engine == "auto"
    hole = square_hole(gravel.shape, 20, 50, 10, 70)
    from weft.core.fill.method import fill_image

    assert np.array_equal(fill(gravel, hole, patch=5, seed=3), fill_image(gravel, hole, params=params, rng=3)[0])
    with pytest.raises(InvalidParameter, match="engine"):
        FillParams(engine="pixel")


def test_python_api_refusals(gravel):
    with pytest.raises(WeftError, match="nothing to fill: give a mask"):
        fill(gravel)
    with pytest.raises(WeftError, match="nothing to fill: the mask has no white pixel"):
        fill(gravel, np.zeros(gravel.shape, bool))
    with pytest.raises(WeftError, match="the mask is 10x10 but the image is 96x96"):
        fill(gravel, np.ones((10, 10), bool))
    with pytest.raises(WeftError, match="covers the whole image: nothing is left to copy from"):
        fill(gravel, np.ones(gravel.shape, bool))
    with pytest.raises(WeftError, match="nothing to fill: give a mask"):
        fill(gravel, size=(96, 96))  # the image's own size grows nothing
    with pytest.raises(InvalidParameter, match="parameter 'size' = 64x64 is smaller than the 96x96 image"):
        fill(gravel, size=(64, 64))
    with pytest.raises(InvalidParameter, match="cannot be given together"):
        FillParams(extend=(1, 1, 1, 1), size=(200, 200))
    with pytest.raises(InvalidParameter, match="the left margin -1 is outside"):
        fill(gravel, extend=(-1, 0, 0, 0))


def test_engines_listed():
    assert {"auto", "quilt", "patchmatch", "hybrid"} == set(ENGINES)
    assert FillParams().engine == "auto"


def test_auto_runs_hybrid_where_no_edges_cross_and_patchmatch_for_the_edge_guide(gravel):
    """``auto`` (the default) is the engine it names in the figures, and its pixels are that
    engine's: hybrid for a hole inside a colour picture that cuts no edge the guide pairs, inside a
    grey picture, along the border, an uncrop and a large patch; patchmatch when ``structure`` = yes
    asks for the edge guide (where the guide finds edges: tests/core/test_fill_structure.py)."""
    big = np.ascontiguousarray(load_image(example("chelsea")).image[:160, :200])
    photo = big[:96, :120]
    assert photo.ndim == 3
    hole = square_hole(photo.shape)
    grey_rgb = np.repeat(gravel[..., None], 3, axis=2)
    border = np.zeros(photo.shape[:2], bool)
    border[:, :20] = True
    cases = [
        ("hybrid", photo, dict(mask=hole)),
        ("hybrid", gravel, dict(mask=square_hole(gravel.shape))),
        ("hybrid", grey_rgb, dict(mask=square_hole(gravel.shape))),
        ("hybrid", photo, dict(mask=border)),
        ("hybrid", photo, dict(extend=(0, 0, 16, 0))),
        ("hybrid", big, dict(mask=square_hole(big.shape, 70, 100, 80, 120), patch=64)),
        ("patchmatch", photo, dict(mask=hole, structure="yes")),
    ]
    from weft.core.fill.method import fill_image
    from weft.core.geometry import Margins

    for expected, image, kw in cases:
        mask = kw.pop("mask", None)
        if "extend" in kw:
            kw["extend"] = Margins.coerce(kw["extend"])
        out, figures = fill_image(image, mask, params=FillParams(**kw), rng=2)
        assert figures["engine"] == expected, (expected, kw)
        named = {"engine": expected, **kw, "patch": kw.get("patch", figures["patch"])}
        assert np.array_equal(out, fill(image, mask, seed=2, **named))


def test_studio_shows_the_patch_the_run_takes_or_none(gravel):
    """The studio's "auto" patch (beside its box, and the centre of a variations range) is the patch
    the run then reports, or nothing when the run decides it from the pixels: ``auto`` on a colour
    picture with a hole (patchmatch's 7 where the edge guide pairs edges, else the hybrid's); a named
    engine its own; a patch given is not resolved."""
    from weft.core.fill.method import STUDIO, fill_image

    colour = np.ascontiguousarray(load_image(example("chelsea")).image[:96, :120])
    small = np.ascontiguousarray(gravel[:60, :60])
    for image, params, shown in (
        (colour, FillParams(), False),
        (colour, FillParams(structure="yes"), True),
        (gravel, FillParams(), True),
        (small, FillParams(), True),
        (colour, FillParams(engine="hybrid"), True),
        (gravel, FillParams(extend=(0, 0, 30, 0)), True),
        (gravel, FillParams(engine="quilt", extend=(0, 0, 16, 0)), True),
    ):
        shapes = {"image": image.shape}
        mask = None
        if params.extend is None:
            mask = square_hole(image.shape)
            shapes["mask"] = mask.shape
        resolved = STUDIO.resolved(params, shapes)
        _, figures = fill_image(image, mask, params=params, rng=0)
        assert resolved == ({"patch": figures["patch"]} if shown else {}), (image.shape, params, figures)
    assert STUDIO.resolved(FillParams(engine="hybrid", extend=(0, 0, 30, 0)), {"image": gravel.shape}) == {"patch": 32}
    assert STUDIO.resolved(FillParams(), {"image": (300, 400, 3), "mask": (300, 400)}) == {}
    assert STUDIO.resolved(FillParams(engine="patchmatch"), {"image": (300, 400, 3)}) == {"patch": 7}
    assert STUDIO.resolved(FillParams(engine="quilt", extend=(0, 0, 16, 0)), {"image": (300, 400, 3)}) == {"patch": 24}
    assert STUDIO.resolved(FillParams(engine="quilt", extend=(0, 0, 40, 0)), {"image": (300, 400, 3)}) == {"patch": 48}
    assert STUDIO.resolved(FillParams(engine="hybrid"), {"image": (300, 400)}) == {"patch": 64}
    assert STUDIO.resolved(FillParams(patch=9), {"image": (96, 120, 3)}) == {}
    assert STUDIO.resolved(FillParams(), {}) == {}


def test_auto_shows_no_hybrid_block_on_a_colour_hole_it_fills_with_patchmatch():
    """A colour picture whose hole cuts a rim the edge guide pairs: ``auto`` runs patchmatch with its
    7-px patch, and the studio does not show the hybrid's 64 beside the "auto" box."""
    from weft.core.fill.method import STUDIO, fill_image

    from .test_fill_structure import _hole_on, _picture

    image, _ = _picture()
    hole = _hole_on(80, 225, 16)
    _, figures = fill_image(image, hole, params=FillParams(), rng=1)
    assert figures["engine"] == "patchmatch" and figures["patch"] == 7
    resolved = STUDIO.resolved(FillParams(), {"image": image.shape, "mask": hole.shape})
    assert resolved in ({}, {"patch": 7}), resolved


@pytest.mark.parametrize("engine", sorted(ENGINE_FUNCS))
def test_progress_reaches_the_end_and_cancel_stops(engine, gravel):
    from weft.core.errors import Cancelled
    from weft.core.jobs import CancelToken

    hole = square_hole(gravel.shape)
    seen = []
    fill(gravel, hole, engine=engine, seed=0, progress=seen.append)
    assert seen and seen[-1].fraction == 1.0 and all(a.done <= b.done for a, b in zip(seen, seen[1:], strict=False))
    token = CancelToken()
    token.cancel()
    with pytest.raises(Cancelled):
        fill(gravel, hole, engine=engine, seed=0, cancel=token)


@pytest.mark.parametrize("case", ["hole", "uncrop"])
def test_every_scalar_figure_has_a_human_reading_in_the_studio_description(case, brick):
    """As tests/core/test_figures.py does for the studio's methods (fill joins them once the studio draws masks)."""
    import json
    import re

    from weft.core import registry
    from weft.core.fill.method import STUDIO

    method = registry.get("fill")
    inputs = {"image": brick[:64, :64]}
    params = {"extend": (8, 0, 8, 4)} if case == "uncrop" else {"patch": 9}
    if case == "hole":
        inputs["mask"] = square_hole((64, 64), 20, 36, 20, 40).astype(np.float32)
    result = method.run(inputs, method.params(**params), rng=0)
    scalars = {k for k, v in result.figures.items() if v is not None and not isinstance(v, (list, tuple, dict))}
    assert scalars >= {"engine", "hole_pixels"} and not scalars - set(STUDIO.figures)
    words = STUDIO.describe(result.figures)
    assert len(words) == len(scalars) and not any(re.search(r"\b[a-z0-9]+(?:_[a-z0-9]+)+\b", t) for t in words)
    json.dumps(dict(result.figures))
    assert STUDIO.canvas == "image" and [g.kind for g in STUDIO.geometry] == ["mask", "margins", "mask"]
    assert STUDIO.geometry[0].input == "mask" and STUDIO.geometry[1].param == "extend"
    assert STUDIO.geometry[2].input == "source_mask" and STUDIO.geometry[2].empty_is_all  # the sampling area


def test_numpy_cut_and_solver_agree_with_the_kernels():
    """weft.core.fill.cut (numpy) against weft.core.seams / weft.core._kernels.poisson (numba)."""
    from weft.core._kernels.poisson import poisson_cg as kernel_cg
    from weft.core.fill.cut import _vertical_path, min_cut, poisson_cg
    from weft.core.seams import min_cut_mask, min_error_path

    rng = np.random.default_rng(5)
    err = rng.random((20, 9))
    assert np.array_equal(_vertical_path(err), min_error_path(err))  # the same path (ties aside: random costs)
    assert np.array_equal(min_cut(err, left=9), min_cut_mask(err, left=9))
    e2 = rng.random((16, 16))
    both = min_cut(e2, right=5, bottom=4)
    assert np.array_equal(both, min_cut_mask(e2, right=5, bottom=4))
    img = rng.random((12, 12, 2))
    hole = np.zeros((12, 12), bool)
    hole[3:9, 4:10] = True
    ys, xs = np.nonzero(hole)
    index = -np.ones((12, 12), int)
    index[ys, xs] = np.arange(len(ys))
    nbr = np.full((len(ys), 4), -1)
    ndeg = np.zeros(len(ys))
    rhs = np.zeros((len(ys), 2))
    for k, (dy, dx) in enumerate(((1, 0), (-1, 0), (0, 1), (0, -1))):
        qy, qx = ys + dy, xs + dx
        ndeg += 1
        j = index[qy, qx]
        nbr[:, k] = j
        rhs[j < 0] += img[qy[j < 0], qx[j < 0]]
    a = poisson_cg(nbr, ndeg, rhs, np.zeros_like(rhs), 1e-10, 500)
    b = np.zeros_like(rhs)
    kernel_cg(nbr, ndeg, rhs, b, 1e-10, 500)
    assert np.allclose(a, b, atol=1e-7)


def test_a_default_patch_fits_a_small_image_and_an_even_pixel_patch_is_the_next_odd_one(gravel):
    small = gravel[:20, :20]
    hole = square_hole(small.shape, 8, 13, 8, 13)
    for engine in ENGINES:  # quilt's default block is 24: larger than the image
        out = fill(small, hole, engine=engine, seed=0, band=0)
        assert np.array_equal(out[~hole], small[~hole]) and np.isfinite(out).all()
    half = np.zeros((20, 20), bool)
    half[:, 8:] = True  # the source is 8 px wide: a 9x9 patch does not fit
    with pytest.raises(WeftError, match="needs at least one whole 9x9 patch"):
        fill(small, half, engine="quilt", patch=9)
    with pytest.raises(InvalidParameter, match="parameter 'patch' = 64 is outside 3..63 for the patchmatch engine"):
        FillParams(engine="patchmatch", patch=64)


def test_band_leaves_a_step_the_texture_itself_has(monkeypatch):
    """Only the part of a seam's step beyond twice the texture's own step is spread: a noise texture
    whose hole holds its own pixels changes far less than when every step is spread, and a real step
    at the edge is still spread."""
    from weft.core.fill import band

    rng = np.random.default_rng(0)
    img = (rng.random((48, 48, 1)) * 0.1 + 0.4).astype(np.float32)
    hole = np.zeros((48, 48), dtype=bool)
    hole[12:36, 12:36] = True
    ring = band_region(hole, 2)
    kept = np.abs(blend_band(img, hole, 2) - img)[ring].mean()
    stepped = img.copy()
    stepped[hole] += 0.5
    assert np.abs(blend_band(stepped, hole, 2) - stepped)[ring].mean() > 0.05
    monkeypatch.setattr(band, "STEP", 0.0)
    every = np.abs(blend_band(img, hole, 2) - img)[ring].mean()
    assert kept < 0.5 * every


def test_quilt_continues_neighbouring_copies(monkeypatch):
    """A block that continues a neighbour's copy is preferred when it costs little more: the fill
    holds fewer seams, so more of its 7x7 windows are verbatim known ones (lower coherence)."""
    from weft.core.fill import quilt

    img = load_image(example("gravel")).image[:160, :160]
    hole = np.zeros(img.shape, dtype=bool)
    hole[40:100, 40:100] = True
    default = [metrics.fill_coherence(fill_quilt(img, hole, rng=s), hole) for s in range(3)]
    monkeypatch.setattr(quilt, "COHERE", 0.0)
    seams = [metrics.fill_coherence(fill_quilt(img, hole, rng=s), hole) for s in range(3)]
    assert np.median(default) < 0.9 * np.median(seams)


def test_quilt_colour_guide_only_on_colour(monkeypatch):
    """The coarse colour guide steers the blocks of a colour image (the output changes without it)
    and plays no part on a grey one (the same output with and without it)."""
    from weft.core.fill import quilt

    photo = load_image(example("brick")).image[:96, :96]
    rng = np.random.default_rng(0)
    colour = np.stack([photo, photo[::-1], rng.random(photo.shape, dtype=np.float32)], axis=2)
    hole = square_hole(photo.shape)
    guided, grey = fill_quilt(colour, hole, patch=16, rng=1), fill_quilt(photo, hole, patch=16, rng=1)
    monkeypatch.setattr(quilt, "GUIDE", 0.0)
    assert not np.array_equal(fill_quilt(colour, hole, patch=16, rng=1), guided)
    assert np.array_equal(fill_quilt(photo, hole, patch=16, rng=1), grey)


def test_quilt_fill_order_puts_an_edge_first_on_colour_only(monkeypatch):
    """Step 1's structure term: of two front pixels whose windows hold as many known pixels, the
    one whose known pixels carry an edge is filled first on a colour image; a grey image keeps the
    count alone (the same output with and without the term)."""
    from weft.core.fill import quilt

    h, w, b = 64, 96, 16
    img = np.full((h, w, 3), 0.5, np.float32)
    img[:, 70:] = (0.8, 0.2, 0.1)  # an edge at x = 70, in the right half only
    hole = np.zeros((h, w), dtype=bool)
    hole[24:40, 8:88] = True  # a slot across both halves: the front is alike on both sides
    known = ~hole
    canvas = np.where(hole[..., None], 0.0, img).astype(np.float32)
    plain = np.full((h, w), -1.0, np.float32)
    quilt._score(known, plain, b, 0, h, 0, w)
    boosted = np.full((h, w), -1.0, np.float32)
    quilt._score(known, boosted, b, 0, h, 0, w, quilt._edges(canvas, known))
    assert plain[24, 30] == plain[24, 70] > 0  # the count alone cannot tell them apart
    assert boosted[24, 70] > 1.5 * boosted[24, 30]  # the edge's window goes first
    py, px = np.unravel_index(int(np.argmax(boosted)), boosted.shape)
    assert abs(px - 70) <= b // 2

    photo = load_image(example("brick")).image[:96, :96]
    square = square_hole(photo.shape)
    grey = fill_quilt(photo, square, patch=16, rng=1)
    as_rgb = np.repeat(photo[..., None], 3, axis=2)  # a grey picture stored as RGB is grey too
    grey_rgb = fill_quilt(as_rgb, square, patch=16, rng=1)
    monkeypatch.setattr(quilt, "DATA", 0.0)
    assert np.array_equal(fill_quilt(photo, square, patch=16, rng=1), grey)
    assert np.array_equal(fill_quilt(as_rgb, square, patch=16, rng=1), grey_rgb)


def test_batched_cut_is_each_sides_own_cut():
    """min_cut runs a block's strips of one shape in one batched programme: the result is still the
    intersection of each side's own cut, ties (the large constant of known pixels) included."""
    from weft.core.fill.cut import _vertical_path, min_cut

    rng = np.random.default_rng(11)
    for _ in range(50):
        err = rng.integers(0, 3, (24, 24)).astype(np.float64)
        err[rng.random((24, 24)) < 0.3] = 1e6
        sides = {k: int(v) for k, v in zip(("left", "top", "right", "bottom"), rng.integers(0, 9, 4), strict=True)}
        alone = np.ones((24, 24), bool)
        for k, v in sides.items():
            if v:
                alone &= min_cut(err, **{k: v})
        assert np.array_equal(min_cut(err, **sides), alone)
    e = np.array([[5.0, 1.0, 1.0], [1.0, 1.0, 5.0], [5.0, 5.0, 1.0]])
    assert _vertical_path(e).tolist() == [1, 1, 2]  # a tie in the first row (3 at columns 1 and 2): the lowest


def test_quilt_refines_colour_pictures_only():
    """Step 7: on a colour photo the quilt ends with the patch-search refine over the hole and the
    band (its block seams move to where copies agree: lower coherence), known pixels beyond the band
    stay bit for bit, a seed gives the same pixels; a grey picture (or grey stored as RGB) is not
    refined, and the method then blends the band by Poisson as before."""
    from weft.core.fill.quilt import refines

    photo = load_image(example("coffee")).image
    hole = np.zeros(photo.shape[:2], dtype=bool)
    hole[60:110, 180:230] = True
    cut = band_region(hole, 2) & ~hole
    refined = [fill_quilt(photo, hole, patch=16, rng=s, cuttable=cut) for s in (0, 1)]
    plain = [fill_quilt(photo, hole, patch=16, rng=s, cuttable=cut, refine=False) for s in (0, 1)]
    coh = [metrics.fill_coherence(o, hole, photo) for o in refined]
    coh_plain = [metrics.fill_coherence(o, hole, photo) for o in plain]
    assert np.mean(coh) < 0.95 * np.mean(coh_plain)  # (7.48 against 8.18)
    beyond = ~hole & ~cut
    assert all(np.array_equal(o[beyond], photo[beyond]) for o in refined)
    assert np.array_equal(fill_quilt(photo, hole, patch=16, rng=1, cuttable=cut), refined[1])
    assert refines(photo, hole) and not refines(photo, hole, refine=False)

    grey = load_image(example("brick")).image[:96, :96]
    square = square_hole(grey.shape)
    assert not refines(grey, square) and not refines(np.repeat(grey[..., None], 3, axis=2), square)
    assert np.array_equal(
        fill_quilt(grey, square, patch=16, rng=1), fill_quilt(grey, square, patch=16, rng=1, refine=False)
    )


@pytest.mark.slow
def test_default_fill_loads_neither_numba_nor_numpy_ma():
    """The default engine's whole path (quilt, its refine on colour, the band), and ``--structure``'s
    (its edges and patchmatch), run in numpy and OpenCV: a ``weft fill`` process loads no numba (its
    import and cache loads are a noticeable part of a short run) and no numpy.ma (np.percentile
    imports it, for two percentiles)."""
    import subprocess
    import sys

    script = """
import sys
import numpy as np
from weft.core.fill import fill
img = np.random.default_rng(0).random((64, 64, 3), dtype=np.float32)
hole = np.zeros((64, 64), bool)
hole[20:40, 24:44] = True
for image in (img, img[..., 0]):
    for structure in ("no", "yes"):
        out = fill(image, hole, seed=1, structure=structure)
        assert np.array_equal(out[:10], image[:10])
print(" ".join(m for m in ("numba", "numpy.ma", "scipy.sparse", "weft.core._kernels") if m in sys.modules) or "none")
"""
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "none"


def test_refine_percentile_is_numpys():
    from weft.core.fill.common import percentile

    rng = np.random.default_rng(2)
    for n in (1, 2, 3, 10, 999):
        a = np.round(rng.random(n) * 10, 1)
        for q in (0, 25, 50, 75, 99.5):
            assert percentile(a, q) == float(np.percentile(a, q))


@pytest.mark.parametrize("engine", ["quilt", "hybrid"])
def test_a_small_hole_in_a_large_picture_is_filled_from_its_neighbourhood(engine):
    """A 20 px hole in a 1024² picture: the method runs the engine on the hole's bounding box grown
    by NEAR and two patches (what its copies can come from), so the fill equals the fill of that part
    alone, and every pixel beyond it is the picture's own; a source mask, which may lie anywhere,
    and a neighbourhood over a quarter of the picture keep the whole picture."""
    from weft.core.fill.common import NEAR, neighbourhood

    rng = np.random.default_rng(4)
    img = cv2.resize(rng.random((64, 64, 3), dtype=np.float32), (1024, 1024), interpolation=cv2.INTER_CUBIC)
    img = np.clip(img, 0, 1)
    hole = np.zeros((1024, 1024), bool)
    hole[500:520, 700:720] = True
    near = neighbourhood(hole, ~hole, 24)
    m = NEAR + 48
    assert near == (slice(500 - m, 520 + m), slice(700 - m, 720 + m))
    patch = 48 if engine == "hybrid" else FillParams(engine=engine).resolved_patch()
    near = neighbourhood(hole, ~hole, patch)
    out = fill(img, hole, engine=engine, patch=patch, seed=3)
    alone = fill(img[near], hole[near], engine=engine, patch=patch, seed=3)
    assert np.array_equal(out[near], alone)
    outside = np.ones((1024, 1024), bool)
    outside[near] = False
    assert np.array_equal(out[outside], img[outside])
    source = np.zeros_like(hole)
    source[:100, :100] = True  # a source mask far from the hole
    assert neighbourhood(hole, source, 24) is None
    big = np.zeros_like(hole)
    big[200:800, 200:800] = True
    assert neighbourhood(big, ~big, 24) is None


def test_a_grey_neighbourhood_of_a_colour_picture_is_blended_as_the_engine_filled_it():
    """The quilt engine refines colour pictures and leaves grey ones to the Poisson band; on a large
    picture it fills the hole's neighbourhood alone, so the band is decided on that part too: a hole
    in a grey region of a picture coloured only far away gets the band, as the part alone does."""
    from weft.core.fill.common import neighbourhood

    rng = np.random.default_rng(5)
    grey = cv2.resize(rng.random((64, 64), dtype=np.float32), (1024, 1024), interpolation=cv2.INTER_CUBIC)
    img = np.repeat(np.clip(grey, 0, 1)[..., None], 3, axis=2)
    img[:64, :64, 0] = 1.0  # colour, far from the hole
    hole = np.zeros((1024, 1024), bool)
    hole[600:630, 700:730] = True
    near = neighbourhood(hole, ~hole, 24)
    out = fill(img, hole, seed=2, engine="quilt")
    assert np.array_equal(out[near], fill(img[near], hole[near], seed=2, engine="quilt"))


def test_quilt_draws_no_mortar_line_into_a_thin_gap(monkeypatch):
    """The quilt's step 5 on a thin gap: the benchmark's brick box ends 5 px above a mortar line,
    so its last row of blocks fills an 8-px gap between filled rows and the dark rows above that
    line; the overlap constrains nothing there, and at seeds 1 and 9 a continued copy drew a second
    mortar line into it (the seam figure 0.26 over the truth's). A copy is now continued into a thin
    gap only if it agrees with the gap's diffusion from its sides."""
    from weft.core.fill import quilt

    from benchmarks.fill import build_brick

    case = build_brick()
    image = case.known_part.astype(np.float32) / 255.0
    truth = metrics.fill_seam(case.truth.astype(np.float32) / 255.0, case.hole)

    def excess(seed):
        return metrics.fill_seam(fill(image, case.hole, seed=seed, engine="quilt"), case.hole) - truth

    assert all(abs(excess(s)) <= 0.15 for s in (1, 9))
    monkeypatch.setattr(quilt, "GAP", 0.0)
    assert excess(1) > 0.15  # without the term, the second line is back


def _parity_halves(seed=0, h=400, w=900, split=300):
    """A blurred-noise picture whose columns left of ``split`` hold even 8-bit levels and the others
    odd ones: the same texture to the SSD (1/255 apart), told apart by the parity of a copied pixel."""
    rng = np.random.default_rng(seed)
    noise = cv2.GaussianBlur(rng.standard_normal((h, w)).astype(np.float32), (0, 0), 2.0)
    levels = np.clip(np.rint(128 + 60 * noise / noise.std()), 2, 252).astype(np.int32) // 2 * 2
    levels[:, split:] += 1
    return levels.astype(np.float32) / 255.0


def test_quilt_copies_from_the_nearest_reach_that_has_a_block():
    """A hole wider than twice the quilt's REACH: a window in its middle has no whole source block
    within REACH; its blocks now come from the nearest reach that has one (the odd levels around the
    hole), not from anywhere in the picture (the even ones, 220 px left of the hole)."""
    img = _parity_halves()
    hole = np.zeros(img.shape, dtype=bool)
    hole[70:330, 520:780] = True
    out = fill_quilt(img, hole, patch=16, rng=3)
    levels = np.rint(out[hole] * 255).astype(np.int32)
    assert np.all(levels % 2 == 1)


@pytest.mark.parametrize("seed", range(4))
def test_quilt_front_finds_numpys_first_maximum(seed):
    """The fill front's strip maxima give ``np.argmax``'s answer (the first maximum in scan order,
    ties included) after any run of updates."""
    from weft.core.fill import quilt

    rng = np.random.default_rng(seed)
    score = rng.integers(-1, 4, size=(97, 61)).astype(np.float32)  # many ties
    front = quilt._Front(score)
    for _ in range(50):
        assert front.first_max() == np.unravel_index(int(np.argmax(score)), score.shape)
        y0 = int(rng.integers(0, 97))
        y1 = int(rng.integers(y0 + 1, 98))
        score[y0:y1, int(rng.integers(0, 61)) :] = rng.integers(-1, 6, size=1)[0]
        front.update(y0, y1)


def test_an_extension_along_the_border_is_quilted_with_larger_blocks():
    """A hole along the canvas border more than 24 px deep gets the quilt's BORDER_BLOCK (48 px): the
    bundled brick's right third grown back from the rest meets the known part about as the truth
    does (24-px blocks drift from the bricks' joints block by block: a visible edge, +1.75 over it).
    A small hole that touches the border keeps 24."""
    from weft.core.fill.params import BORDER_BLOCK

    full = load_image(example("brick")).image
    h, w = full.shape[:2]
    cut = int(w * 0.68)
    hole = np.zeros((h, w), dtype=bool)
    hole[:, cut:] = True
    truth = metrics.fill_seam(full, hole)
    out, figures = fill_image_figures(full[:, :cut], extend=(0, 0, w - cut, 0), seed=0, engine="quilt")
    assert figures["patch"] == BORDER_BLOCK and out.shape == full.shape
    assert abs(metrics.fill_seam(out, hole) - truth) <= 0.3
    small, _ = fill_image_figures(full[:, :cut], extend=(0, 0, w - cut, 0), seed=0, patch=24, engine="quilt")
    assert metrics.fill_seam(small, hole) - truth > 1.0
    from weft.core.fill.method import fill_image

    dab = np.zeros((h, w), dtype=bool)
    dab[:12, 100:130] = True  # a small hole on the border keeps the 24-px block
    assert fill_image(full, dab, params=FillParams(engine="quilt"), rng=0)[1]["patch"] == 24


def fill_image_figures(image, seed, **params):
    """``fill_image`` with these parameters: (output, figures)."""
    from weft.core.fill.method import fill_image

    return fill_image(image, None, params=FillParams(**params), rng=seed)


def test_a_grey_picture_stored_as_rgb_gets_the_thin_gap_check_too(monkeypatch):
    """The thin-gap check is for pictures without colour, however they are stored: the benchmark's
    brick as RGB fills as the grey one does, and without the check its seed 1 draws the line again."""
    from weft.core.fill import quilt

    from benchmarks.fill import build_brick

    case = build_brick()
    grey = case.known_part.astype(np.float32) / 255.0
    rgb = np.repeat(grey[..., None], 3, axis=2)
    out = fill(rgb, case.hole, seed=1, engine="quilt")
    assert np.allclose(out, fill(grey, case.hole, seed=1, engine="quilt")[..., None], atol=1e-5)
    truth = metrics.fill_seam(case.truth.astype(np.float32) / 255.0, case.hole)
    assert abs(metrics.fill_seam(out, case.hole) - truth) <= 0.15
    monkeypatch.setattr(quilt, "GAP", 0.0)
    assert metrics.fill_seam(fill(rgb, case.hole, seed=1, engine="quilt"), case.hole) - truth > 0.15
