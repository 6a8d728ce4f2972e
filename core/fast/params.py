"""Parameters of fast texture transfer (Ashikhmin 2003): one Spec per option, and what "auto" resolves to."""

from __future__ import annotations

from dataclasses import dataclass

from ..errors import InvalidParameter
from ..params import Params, param

MODES = ("auto", "transfer", "synthesis", "superres", "novel")
# Metric codes of the kernel (weft.core._kernels.fast), which is imported on first use: importing numba
# costs a quarter of a second that `weft --help` or another method's run need not pay.
METRICS = {"full": 0, "target": 1, "artistic": 2}


@dataclass(frozen=True)
class FastParams(Params):
    """Parameters of fast texture transfer (Ashikhmin 2003)."""

    mode: str = param(
        "auto",
        choices=MODES,
        help="what is made: transfer = the target rendered in the texture; synthesis = more texture; "
        "superres = the picture magnified from itself; novel = the picture restyled from itself "
        "(Fig. 2); auto: transfer with a target, superres with --magnify > 1, else synthesis",
    )
    metric: str = param(
        "full",
        choices=tuple(METRICS),
        help="what a candidate must match: full = the result so far and the picture (eq. 1); target"
        " = the picture only (most faithful); artistic = tones and strokes, for drawings and "
        "paintings",
    )
    n: int = param(
        5,
        lo=3,
        hi=15,
        step=2,
        symbol="n",
        help="side of the neighbourhood compared (odd): small copies fine "
        "grain, large carries larger structures of the texture",
    )
    p: float | None = param(
        None,
        kind="float",
        lo=0.0,
        hi=1.0,
        optional=True,
        symbol="p",
        step=0.01,
        help="chance of a random candidate: 0 gives long coherent pieces of the texture, higher values"
        " follow the picture in smaller pieces; default 0.05 (super-resolution 0)",
    )
    p_l: float | None = param(
        None,
        kind="float",
        lo=0.0,
        hi=1.0,
        optional=True,
        symbol="p_l",
        step=0.01,
        help="chance of the candidate at the same place in the picture (x/m, y/m): higher keeps the "
        "original layout; default 0 (super-resolution 0.03)",
    )
    magnify: int = param(
        1,
        lo=1,
        hi=16,
        symbol="m",
        help="magnification: the result is the picture magnified m times (superres, novel); also "
        "the scale of the same-place candidate",
    )
    w: float = param(
        1.0,
        lo=0.0,
        hi=100.0,
        symbol="w",
        step=0.1,
        help="artistic metric: weight of the tones (neighbourhood averages) against the strokes; "
        "higher follows the picture's tones more closely",
    )
    target_weight: float = param(
        1.0,
        lo=0.0,
        hi=100.0,
        step=0.1,
        help="full metric: weight of matching the picture against matching the result so "
        "far; higher is more faithful, lower more coherent",
    )
    iterations: int = param(
        1, lo=1, hi=20, help="synthesis passes: later passes match every pixel again and smooth out early mistakes"
    )
    remap: bool = param(
        True,
        help="match against the texture's brightness remapped to the picture's mean and "
        "contrast (Hertzmann et al.), so a dark texture can render a bright picture; the"
        " output keeps the texture's own values",
    )
    colour: str = param(
        "auto",
        choices=("auto", "target", "source"),
        help="colour of the result: target keeps the picture's colours (YIQ chroma); source copies "
        "the texture's colours",
    )
    size: tuple[int, int] | None = param(
        None,
        kind="size",
        lo=8,
        hi=16384,
        optional=True,
        help="output size WIDTHxHEIGHT for synthesis; default twice the texture",
    )

    def check(self) -> None:
        if self.n % 2 == 0:
            raise InvalidParameter(f"parameter 'n' = {self.n} must be odd (3, 5, 7, ...)", name="n", value=self.n)

    def resolved(self, has_target: bool) -> FastParams:
        """The parameters with ``mode``, ``p``, ``p_l`` and ``colour`` made explicit."""
        mode = self.mode
        if mode == "auto":
            mode = "transfer" if has_target else ("superres" if self.magnify > 1 else "synthesis")
        if mode == "transfer" and not has_target:
            raise InvalidParameter("mode 'transfer' needs a target image (--target)", name="mode", value=mode)
        if mode != "transfer" and has_target:
            raise InvalidParameter(
                f"mode '{mode}' takes no target image; drop --target or use mode transfer", name="mode", value=mode
            )
        if self.metric in ("target", "artistic") and mode == "synthesis":
            raise InvalidParameter(
                f"metric '{self.metric}' needs a target; synthesis has none (use metric full)",
                name="metric",
                value=self.metric,
            )
        p = self.p if self.p is not None else (0.0 if mode == "superres" else 0.05)
        p_l = self.p_l if self.p_l is not None else (0.03 if mode == "superres" else 0.0)
        colour = self.colour
        if colour == "auto":
            colour = "target" if mode in ("transfer", "novel") else "source"
        return self.replace(mode=mode, p=p, p_l=p_l, colour=colour)
