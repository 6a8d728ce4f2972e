"""Patch boundary matching (Smith & Bhalerao §4): partial correlation and the shaker box.

Once every patch has its linear transform, its translation can be chosen for continuity with its
neighbours rather than for fidelity to the target (texture transfer wants "a new textured image
with a resemblance to the original", in which "each patch must merge seamlessly into the next"):

* ``partial`` -- one raster pass; each patch's translation is recalculated to match the patches
  already synthesized, over the non-rectangular overlap they leave (Fig. 3a);
* ``shaker`` -- the shaker box: starting from those translations (or the analysis ones), every
  iteration visits all patches in a random order and moves each to match *all* its neighbours
  (a full correlation, Fig. 3b). Convergence is forced: the change allowed from one iteration to
  the next starts at B/4 and shrinks by one every ``per_radius`` iterations (five in the paper,
  "typically after around 20 iterations"); it stops when no patch moves or no change is allowed.

The criterion. Eq. 24 correlates the mask (the synthesized neighbours) with the shifted
prototype; here it is completed into the window-weighted squared difference between the patch
and each overlapping neighbour, ``E_k(t) = Σ_b Σ_y W_k W_b (p_k,t - p_b)²``, which is eq. 24's
cross term ``-2 Σ W_k other(y) p_t(y)`` plus the energy of the shifted prototype under the
neighbours' windows. Unlike the bare correlation, minimising ``E_k`` is exact coordinate descent on
the *total boundary error* ``Σ_pairs Σ_y W_a W_b (p_a - p_b)²`` (summed over the image's pixels),
so with the current translation always among the choices (and ties keeping it) the total can never
increase: that is what makes the forced schedule converge. The total is reported per iteration.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import InvalidParameter
from ..jobs import CancelToken, Progress, ProgressReporter
from ..params import as_rng
from .model import AffineModel, Prototype, padded
from .spectral import cos2_window
from .synthesis import _as_prototype, compose

MODES = ("none", "partial", "shaker")
STARTS = ("partial", "analysis")


@dataclass(frozen=True)
class BoundaryReport:
    """What boundary matching did.

    Attributes
    ----------
    mode : {"none", "partial", "shaker"}
    iterations : int
        Shaker iterations run (0 for ``partial``).
    errors : list of float
        Total boundary error after the starting pass and after every shaker iteration (sum over
        the image of ``Σ_pairs W_a W_b (p_a - p_b)²``, intensities in [0, 1]); non-increasing
        after the first entry.
    moves : list of int
        Patches whose translation changed, per shaker iteration.
    radii : list of int
        The change allowed in each shaker iteration.
    """

    mode: str
    iterations: int = 0
    errors: list = field(default_factory=list)
    moves: list = field(default_factory=list)
    radii: list = field(default_factory=list)

    def figures(self) -> dict:
        """Short, JSON-serialisable figures for ``--report``."""
        out: dict[str, Any] = {"boundary": self.mode}
        if self.errors:
            out["boundary_error"] = [float(f"{e:.5g}") for e in self.errors]
        if self.mode == "shaker":
            out["shaker_iterations"] = self.iterations
        return out


class _Canvas:
    """The boundary-matching state: frames, translations and the accumulated canvases."""

    def __init__(self, model: AffineModel, proto: Prototype, shifts: np.ndarray):
        from .._kernels import affine as _k

        grid = model.grid
        self.grid = grid
        self.R = grid.radius
        L = grid.block + 2 * self.R
        # matched on the grey of what is drawn: the highpass (add) or the unfiltered grey
        pimg, c = padded(proto.highpass if model.lowpass == "add" else proto.grey)
        frames = np.empty((grid.count, L, L), np.float32)
        _k.warp_frames(pimg, c, c, np.ascontiguousarray(model.sampling), frames)
        frames *= model.alpha.astype(np.float32)[:, None, None]
        self.frames = frames
        self.window = cos2_window(grid.block)
        self.origins = grid.origins()
        self.mask = grid.inside()
        hc, wc = grid.canvas
        self.acc = np.zeros((hc, wc))
        self.acc2 = np.zeros((hc, wc))
        self.wacc = np.zeros((hc, wc))
        self.placed = np.zeros(grid.count, np.bool_)
        self.clock = np.zeros(1, np.int64)
        self.moved_at = np.zeros(grid.count, np.int64)
        self.seen_at = np.full(grid.count, -1, np.int64)
        self.shifts = np.ascontiguousarray(np.clip(np.round(shifts), -self.R, self.R).astype(np.int64))

    def fill(self) -> None:
        from .._kernels import affine as _k

        _k.accumulate(self.frames, self.window, self.origins, self.shifts, self.R, self.acc, self.acc2, self.wacc)
        self.placed[:] = True

    def run(self, order: np.ndarray, radius: int, skip: bool = True) -> int:
        """One pass over ``order``; ``skip``: leave out patches whose neighbours have not moved
        since they were last evaluated (exact, see the kernel)."""
        from .._kernels import affine as _k

        if not skip:
            self.seen_at[:] = -1
        return int(
            _k.boundary_pass(
                self.frames,
                self.window,
                self.origins,
                self.mask,
                self.acc,
                self.acc2,
                self.wacc,
                self.placed,
                self.shifts,
                np.ascontiguousarray(order, dtype=np.int64),
                int(radius),
                self.R,
                self.grid.cols,
                self.clock,
                self.moved_at,
                self.seen_at,
            )
        )

    def total_error(self) -> float:
        """``Σ_image Σ_pairs W_a W_b (p_a - p_b)² = Σ mask (wacc acc2 - acc²)``."""
        return float(np.sum(self.mask * (self.wacc * self.acc2 - self.acc * self.acc)))

    def preview(self, model: AffineModel) -> np.ndarray:
        g = self.grid
        return (
            compose(model, g.crop(self.acc.astype(np.float32))[..., None])
            if model.lowpass == "add"
            else np.clip(g.crop(self.acc.astype(np.float32)), 0.0, 1.0)
        )


def total_boundary_error(model: AffineModel, prototype: Prototype | np.ndarray | None = None) -> float:
    """The total boundary error of a model with its current translations (§4).

    Parameters
    ----------
    model : AffineModel
        Its translations are rounded to whole pixels (as boundary matching uses them).
    prototype : Prototype or patch, optional
        What is rendered (default the model's prototype).

    Returns
    -------
    float
        ``Σ_image Σ_pairs W_a W_b (p_a - p_b)²`` over every pair of overlapping patches, with the
        intensity factors applied: the quantity the shaker box never increases.
    """
    proto = _as_prototype(model, prototype)
    canvas = _Canvas(model, proto, model.shifts)
    canvas.fill()
    return canvas.total_error()


def match_boundaries(
    model: AffineModel,
    mode: str = "shaker",
    *,
    prototype: Prototype | np.ndarray | None = None,
    iterations: int = 20,
    per_radius: int = 5,
    start: str = "partial",
    rng: None | int | np.random.Generator = None,
    progress: Callable[[Progress], None] | None = None,
    cancel: CancelToken | None = None,
) -> tuple[AffineModel, BoundaryReport]:
    """New translations for continuity between patches (§4): partial correlation or shaker box.

    Parameters
    ----------
    model : AffineModel
        Linear transforms and intensity factors to keep; only the translations change.
    mode : {"none", "partial", "shaker"}, default "shaker"
        ``partial``: one raster pass, each patch matched to the already placed ones (Fig. 3a);
        ``shaker``: then (or from the analysis translations, see ``start``) iterations visiting
        every patch in a random order, each matched to all its neighbours (Fig. 3b).
    prototype : Prototype or patch, optional
        The prototype that will be rendered (default the model's): boundaries are matched on
        what is drawn, so a swapped prototype (§4) gets its own translations.
    iterations : int, 1..500, default 20
        Most shaker iterations ("typically after around 20 iterations").
    per_radius : int, >= 1, default 5
        Shaker iterations per search radius; the change allowed starts at B/4 and drops by one
        after every ``per_radius`` iterations (the paper's forced convergence, five per size).
    start : {"partial", "analysis"}, default "partial"
        Shaker starting translations: recalculated by the partial pass (as in the paper's Fig. 4d)
        or those of the analysis (§2.3).
    rng : None, int or Generator
        The random visiting order (same seed, same result).
    progress, cancel
        Progress per patch row (partial pass) and per iteration (shaker), with a preview of the
        synthesized signal; the token is checked as often.

    Returns
    -------
    (AffineModel, BoundaryReport)
        The model with integer translations ``|t| <= B/4``, and what happened.

    Notes
    -----
    The translations searched are integers (as eq. 24's correlation function); the prototype is
    matched on its grey channel with the model's intensity factors applied. The first patch of the
    partial pass, having no neighbour yet, keeps its analysis translation (as does any patch when
    all shifts tie).
    """
    if mode not in MODES:
        raise InvalidParameter(
            f"parameter 'boundary' = {mode!r} is not one of {', '.join(MODES)}", name="boundary", value=mode
        )
    if start not in STARTS:
        raise InvalidParameter(
            f"parameter 'shaker_start' = {start!r} is not one of {', '.join(STARTS)}", name="shaker_start", value=start
        )
    for name, value, lo in (("iterations", iterations, 1), ("per_radius", per_radius, 1)):
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < lo:
            raise InvalidParameter(f"parameter '{name}' = {value!r} must be an integer >= {lo}", name=name, value=value)
    if mode == "none":
        return model, BoundaryReport("none")
    proto = _as_prototype(model, prototype)
    rng = as_rng(rng)
    grid = model.grid
    canvas = _Canvas(model, proto, model.shifts)
    R = canvas.R
    errors: list[float] = []
    moves: list[int] = []
    radii: list[int] = []
    run_partial = mode == "partial" or start == "partial"
    total = (grid.rows if run_partial else 0) + (iterations if mode == "shaker" else 0)
    report = ProgressReporter(progress, "boundary matching", max(total, 1))
    done = 0
    if run_partial:
        for r in range(grid.rows):  # raster order, one patch row at a time
            if cancel is not None:
                cancel.raise_if_cancelled()
            canvas.run(np.arange(r * grid.cols, (r + 1) * grid.cols), R, skip=False)
            done += 1
            report.update(done, preview=lambda: canvas.preview(model))
        canvas.seen_at[:] = -1  # the shaker's first iteration evaluates every patch
    else:
        canvas.fill()
    errors.append(canvas.total_error())
    it = 0
    if mode == "shaker":
        for it in range(1, iterations + 1):
            radius = R - (it - 1) // per_radius
            if radius < 1:  # no change in translation is allowed any more
                it -= 1
                break
            if cancel is not None:
                cancel.raise_if_cancelled()
            moved = canvas.run(rng.permutation(grid.count), radius)
            errors.append(canvas.total_error())
            moves.append(moved)
            radii.append(radius)
            done += 1
            report.update(done, preview=lambda: canvas.preview(model))
            if moved == 0:  # converged
                break
    out = model.with_shifts(canvas.shifts.astype(np.float64))
    return out, BoundaryReport(mode, it if mode == "shaker" else 0, errors, moves, radii)
