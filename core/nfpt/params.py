"""Parameters of ``weft nfpt``: the rectification's (:class:`~weft.core.rectify.WarpParams`) and the
patch synthesis of the frontal texture (Yan, Lee & Lin)."""

from __future__ import annotations

from dataclasses import dataclass

from ..errors import InvalidParameter
from ..params import out_of_range, param
from ..rectify import View, WarpParams

DEFAULT_BLOCK = 48
DEFAULT_OVERLAP = 12


@dataclass(frozen=True)
class NfptParams(WarpParams):
    """Parameters of ``weft nfpt`` (Yan, Lee & Lin): rectification (the fields of ``WarpParams``),
    synthesis, repair, re-projection."""

    size: tuple[int, int] | None = param(
        None,
        kind="size",
        lo=8,
        hi=16384,
        optional=True,
        help="size WIDTHxHEIGHT of the synthesized frontal texture; default twice the rectified one",
    )
    block: int = param(
        DEFAULT_BLOCK,
        lo=8,
        hi=512,
        symbol="B",
        help="side of the square patches copied: larger "
        "keeps larger texture elements (whole bricks) "
        "whole, smaller mixes them more",
    )
    overlap: int = param(
        DEFAULT_OVERLAP,
        lo=2,
        hi=256,
        help="how much each patch overlaps those already placed (the L-shaped neighbourhood): more"
        " matches and hides seams better; at most block/2",
    )
    sigma_d: float | None = param(
        None,
        kind="float",
        lo=0.1,
        hi=256.0,
        optional=True,
        symbol="σ_d",
        step=0.1,
        help="eq. 1: how far from the patch's edge, in pixels, the match still weighs pixels "
        "fully; small = only the edge counts (default overlap / 2)",
    )
    sigma_s: float = param(
        0.35,
        lo=0.01,
        hi=10.0,
        symbol="σ_s",
        step=0.01,
        help="eq. 2: how much the match favours feature pixels, those unlike the patch's "
        "dominant colour (mortar, cracks); smaller weighs features more (intensity 0..1)",
    )
    tol: int = param(
        2, lo=1, hi=64, help="variety: pick at random among the tol best-matching patches (1 = always the best)"
    )
    repair: bool = param(
        True,
        help="steps 4-7: re-make, pixel by pixel, the pixels along each seam where the two "
        "patches disagree, so broken lines join",
    )
    band: int = param(2, lo=1, hi=16, help="repair band: how many pixels on each side of a seam may be re-made")
    threshold: float = param(
        0.1,
        lo=0.0,
        hi=1.0,
        step=0.01,
        help="repair: how different the two patches must be at a pixel (RMS over channels, "
        "intensity 0..1) for it to be re-made; lower repairs more",
    )
    n: int = param(
        5,
        lo=3,
        hi=15,
        step=2,
        help="repair: side of the neighbourhood matched when a pixel is re-made (odd); "
        "larger follows larger structures",
    )
    smooth: bool = param(
        False, help="step 7: blur the re-made pixels slightly (Gaussian) to hide what the repair leaves"
    )
    view: View | None = param(
        None,
        kind="geometry",
        type=View,
        optional=True,
        help="put the result into this view: a JSON file (or the JSON text, starting with {), "
        '{"quad": [[x, y] x 4], "size": [w, h]} or view image_lines + texture frontal_lines; '
        "texture pixel coordinates",
    )
    into_photo: bool = param(
        False,
        help="put the larger synthesized texture back into the photo in place of the textured plane (a bigger wall)",
    )

    def check(self) -> None:
        if self.overlap * 2 > self.block:
            raise out_of_range("overlap", self.overlap, 2, self.block // 2, f"at most half of block = {self.block}")
        if self.n % 2 == 0:
            raise InvalidParameter(f"parameter 'n' = {self.n} must be odd (3, 5, 7, ...)", name="n", value=self.n)
        if self.view is not None and self.into_photo:
            raise InvalidParameter(
                "parameters 'view' and 'into_photo' exclude each other: give one of them", name="view", value=self.view
            )
