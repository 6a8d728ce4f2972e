"""Image quilting's parameters (:class:`QuiltParams`) and the iterative transfer's pass schedule."""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import InvalidParameter
from ..params import Params, out_of_range, param
from .engine import RULES

MODES = ("random", "overlap", "mincut")
CORRESPONDENCES = ("blur", "luminance")

# Defaults that depend on what is being made (see QuiltParams).
SYNTH_BLOCK_SHARE = 7 / 16  # synthesis: the block is this share of the sample's shorter side ...
SYNTH_BLOCK_MAX = 56  # ... at most this (the whole bricks of a 128-px brick sample)
TRANSFER_BLOCK = 9  # Ngo: single-pass transfer 9 / 3
ITERATIVE_BLOCK = 31  # Ngo: iterative transfer starts at 31 / 21 ...
MIN_BLOCK, MIN_OVERLAP = 9, 3  # ... and goes down to 9 / 3
SYNTH_TOL = 2  # synthesis: tol ...
SYNTH_TOL_LARGE, SYNTH_LARGE_BLOCK = 6, 48  # ... and from this block up
CORR_SIGMA = 2.0  # Gaussian blur (pixels) of the luminance correspondence maps ("blur")


@dataclass(frozen=True)
class QuiltParams(Params):
    """Parameters of image quilting (Efros & Freeman §2 synthesis, §3 transfer).

    ``mode`` defaults to mincut, the paper's full method. ``None`` means "derived from what is
    made": ``block`` for synthesis 7/16 of the sample's shorter side rounded, at most 56 and at
    least 2 (:func:`synth_block`; 56 for a 128-px sample), 9 for one transfer pass, 31 for iterative
    transfer; ``overlap`` a sixth of the block rounded up for synthesis (E&F §2.1), a third for one
    transfer pass (Ngo's 9 / 3) and two thirds for iterative transfer (Ngo's 31 / 21); ``tol`` for
    synthesis 2, or 6 from block 48 up (:func:`synth_tol`), and 1 for transfer.

    The papers leave the block to the user: "the block size must be big enough to capture the
    relevant structures in the texture, but small enough so that the interaction between these
    structures is left up to the algorithm" (E&F §2.1). A sample is usually cropped around a few of
    its elements, so the default scales with it: 7/16 of the side holds whole bricks of a brick
    sample while one block stays under a fifth of the sample's area, so no verbatim region nears a
    quarter of the sample; the cap keeps the output of a large sample from being a few large copies
    of it. With a block of 48 or more the min-cut seam rule weighs 24 candidates (tol 6) instead of
    8: the wider overlap has room for a cut along the texture's joints, and the extra candidates find
    it; at smaller blocks they cost time and gain nothing.
    """

    mode: str = param(
        "mincut",
        choices=MODES,
        help="how blocks join: random = side by side (seams show); overlap = matched where they "
        "overlap; mincut = also cut along the least visible path (smoothest)",
    )
    block: int | None = param(
        None,
        kind="int",
        lo=2,
        hi=1024,
        optional=True,
        symbol="B",
        help="size of the pieces copied from the sample: larger keeps whole structures (a brick with"
        " its joints) but repeats more of the sample, smaller breaks them up (default 7/16 of "
        "the texture's shorter side, at most 56; transfer 9, iterative 31)",
    )
    overlap: int | None = param(
        None,
        kind="int",
        lo=1,
        hi=1023,
        optional=True,
        help="how much neighbouring blocks share, the seam is cut inside it: more hides seams "
        "better and costs time; smaller than block (default block/6 rounded up; transfer "
        "block/3, iterative 2*block/3)",
    )
    size: tuple[int, int] | None = param(
        None,
        kind="size",
        lo=1,
        hi=16384,
        optional=True,
        help="output size WIDTHxHEIGHT; default twice the texture's size (transfer: the target's)",
    )
    tol: int | None = param(
        None,
        kind="int",
        lo=1,
        hi=100000,
        optional=True,
        help="variety: each block is drawn at random from the tol best matches; 1 always takes the "
        "best (seamless, but a spot may repeat), more varies the result with rougher seams "
        "(default 2, 6 from block 48; transfer 1); min-cut synthesis keeps, of the 4 x tol best, "
        "the one with the least visible cut",
    )
    rule: str = param(
        "tol",
        choices=RULES,
        help="how a block is picked among the matches: tol = among the tol best; epsilon = any within"
        " (1+epsilon) x the best error; sampled = the best 10% of a random 10% (quicker, "
        "rougher)",
    )
    epsilon: float = param(
        0.1,
        lo=0.0,
        hi=10.0,
        symbol="ε",
        step=0.01,
        help="rule epsilon: how much worse than the best match a block may be; larger gives more"
        " variety and more visible seams",
    )
    tile: bool = param(False, help="make the output a tile: it repeats without a seam left-right and top-bottom")
    poisson: bool = param(
        False,
        help="smooth away colour steps across every seam by a Poisson blend of a band "
        "around it (modes overlap, mincut)",
    )
    band: int = param(
        4,
        lo=1,
        hi=5,
        help="width in pixels of the smoothed band around each seam (with poisson): wider hides larger colour steps",
    )
    iterations: int = param(
        1,
        lo=1,
        hi=10,
        symbol="N",
        help="transfer passes: each pass uses blocks a third smaller and follows the picture's detail more closely",
    )
    alpha: float = param(
        0.1,
        lo=0.0,
        hi=1.0,
        symbol="α",
        step=0.05,
        help="transfer: texture against picture; near 0 the result follows the picture faithfully,"
        " near 1 it stays a clean texture (first pass; later passes go linearly to 0.9)",
    )
    correspondence: str = param(
        "blur",
        choices=CORRESPONDENCES,
        help="transfer: what the picture is matched on: blurred luminance (broad shapes) or"
        " raw luminance (fine detail); ignored when --source-map and --target-map are "
        "given",
    )
    remap: bool = param(
        True,
        help="transfer: give the target's correspondence map the texture's brightness and "
        "contrast first, so dark and bright areas are not all drawn from the texture's "
        "few extreme spots",
    )

    def check(self) -> None:
        if self.block is not None and self.overlap is not None and self.overlap >= self.block:
            raise out_of_range("overlap", self.overlap, 1, self.block - 1, f"must be smaller than block = {self.block}")
        if self.poisson and self.mode == "random":
            raise InvalidParameter(
                "parameter 'poisson' = true needs mode overlap or mincut "
                "(random blocks do not overlap, so there is no seam to blend)",
                name="poisson",
                value=True,
            )


def synth_block(texture_shape: tuple[int, ...]) -> int:
    """The default block of a synthesis from a sample of this shape (see :class:`QuiltParams`).

    Parameters
    ----------
    texture_shape : tuple of int
        The sample's shape (H, W[, C]).

    Returns
    -------
    int
        7/16 of its shorter side rounded half up, at most 56 and at least 2.

    References
    ----------
    Efros & Freeman (2001), §2.1 (the block must capture the texture's structures).
    """
    side = min(texture_shape[:2])
    return max(2, min(SYNTH_BLOCK_MAX, _round_half_up(SYNTH_BLOCK_SHARE * side)))


def synth_tol(block: int) -> int:
    """The default tol of a synthesis with this block (see :class:`QuiltParams`).

    Parameters
    ----------
    block : int
        The block side.

    Returns
    -------
    int
        2, or 6 from block 48 up.
    """
    return SYNTH_TOL_LARGE if block >= SYNTH_LARGE_BLOCK else SYNTH_TOL


# --------------------------------------------------------------------------------------------
# settings of one pass


def _round_half_up(x: float) -> int:
    return int(math.floor(x + 0.5))


def transfer_schedule(
    iterations: int, *, block: int = ITERATIVE_BLOCK, overlap: int | None = None, alpha: float = 0.1
) -> list[tuple[int, int, float]]:
    """Block, overlap and alpha of every pass of iterative texture transfer.

    Parameters
    ----------
    iterations : int
        N >= 1 passes.
    block : int, default 31
        First pass's block side (Ngo's 31).
    overlap : int, optional
        First pass's overlap; default two thirds of the block rounded (21 for 31), Ngo's 31 / 21.
    alpha : float, default 0.1
        First pass's alpha (0..1).

    Returns
    -------
    list of (block, overlap, alpha), one per pass.

    Notes
    -----
    E&F §3: "the block size was reduced by a third each iteration", and
    ``alpha_i = 0.8 (i - 1)/(N - 1) + 0.1``. Here ``b_i = max(b_min, round(2/3 b_{i-1}))`` and
    ``o_i = max(o_min, round(2/3 o_{i-1}))``, rounding halves up, with the floors of Ngo's finest
    scale, ``b_min = min(9, block)`` and ``o_min = min(3, overlap)``, and ``o_i < b_i``. The default
    31 / 21 gives 31/21, 21/14, 14/9, 9/6, 9/4 for N = 5. Alpha runs linearly from the given
    ``alpha`` to 0.9, ``alpha_i = alpha + (0.9 - alpha)(i - 1)/(N - 1)``, which is the papers'
    schedule for the default 0.1; one pass uses ``alpha`` itself.
    """
    if overlap is None:
        overlap = max(1, min(block - 1, _round_half_up(2 * block / 3)))
    b_min, o_min = min(MIN_BLOCK, block), min(MIN_OVERLAP, overlap)
    out = []
    b, o = block, overlap
    for i in range(iterations):
        if i > 0:
            b = max(b_min, _round_half_up(b * 2 / 3))
            o = max(o_min, _round_half_up(o * 2 / 3))
        o = min(o, b - 1)
        a = alpha if iterations == 1 else alpha + (0.9 - alpha) * i / (iterations - 1)
        out.append((b, o, float(a)))
    return out
