"""The options of one quilting pass, as the engine (``weft.core.quilting.engine``) reads them."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class _Pass:
    mode: str
    block: int
    overlap: int
    rule: str
    tol: int
    epsilon: float
    tile: bool
    poisson: bool
    band: int
    w_overlap: float = 1.0
    w_prev: float = 0.0
    w_corr: float = 0.0
    engine: str = "auto"  # "auto", "numba" or "numpy" (tests compare the two)
    avoid: int | None = (
        None  # radius of _forbid_continuations, -1 off; None: AVOID_RADIUS for synthesis, off for transfer
    )
    usage: float | None = None  # weight of _penalise_usage, 0 off; None: USAGE_WEIGHT for synthesis, off for transfer
    seam_pool: int | None = (
        None  # candidates per tol of the seam rule, 0 off; None: SEAM_POOL for synthesis, off for transfer
    )
