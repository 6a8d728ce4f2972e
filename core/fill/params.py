"""Parameters of ``weft fill`` (:class:`FillParams`) and the engines it can run."""

from __future__ import annotations

from dataclasses import dataclass

from ..errors import InvalidParameter
from ..geometry import MAX_SIDE, Margins
from ..params import Params, param

#: Where the image goes on a larger ``--size`` canvas.
ANCHORS = ("center", "top-left", "top", "top-right", "left", "right", "bottom-left", "bottom", "bottom-right")


#: The engines `--engine` offers (each a function of one signature, see the package docstring).
ENGINES = ("patchmatch", "quilt", "pixel", "hybrid")
#: The default engine: the one that measures best on issue 15's cases (see the package docstring for the figures).
DEFAULT_ENGINE = "quilt"
#: Each engine's patch side when ``patch`` is not given.
DEFAULT_PATCH = {"patchmatch": 7, "quilt": 24, "pixel": 7, "hybrid": 48}


@dataclass(frozen=True)
class FillParams(Params):
    """Parameters of ``weft fill``."""

    engine: str = param(DEFAULT_ENGINE, choices=ENGINES,
                        help="quilt: blocks in fill-front order with min-cut seams (Efros & Freeman); "
                             "pixel: coherent pixel synthesis (Ashikhmin)"
                             "; patchmatch: multi-scale patch search with voting"
                             "; hybrid: quilt, then full-resolution patch search refines the seams")
    patch: int = param(None, kind="int", lo=3, hi=256, optional=True,
                       help="patch side in pixels (quilt, hybrid: the block; pixel: the neighbourhood, odd; patchmatch: at most 63); "
                            "default per engine, smaller on a small image: "
                            + ", ".join(f"{k} {v}" for k, v in DEFAULT_PATCH.items()))
    extend: Margins = param(None, kind="geometry", type=Margins, optional=True,
                            help="uncrop: pixels added on the left, top, right and bottom, filled like the hole")
    size: tuple = param(None, kind="size", lo=1, hi=MAX_SIDE, optional=True,
                        help="uncrop to this canvas size (at least the image's), the image placed by --anchor")
    anchor: str = param("center", choices=ANCHORS, help="where the image sits on a --size canvas")
    band: int = param(2, lo=0, hi=32,
                      help="blend band: known pixels up to this many px from the hole may change (Poisson "
                           "seam band); 0 = they never change")

    def check(self) -> None:
        if self.extend is not None and self.size is not None:
            raise InvalidParameter("parameters 'extend' and 'size' cannot be given together (both set the canvas)",
                                   name="size", value=self.size)
        if self.engine == "patchmatch" and self.patch is not None:
            from .patchmatch import MAX_PATCH

            if self.patch > MAX_PATCH:
                raise InvalidParameter(f"parameter 'patch' = {self.patch} is outside 3..{MAX_PATCH} for the patchmatch "
                                       f"engine", name="patch", value=self.patch)

    def resolved_patch(self) -> int:
        return self.patch if self.patch is not None else DEFAULT_PATCH[self.engine]
