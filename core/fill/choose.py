"""What a fill runs with: the patch side an engine takes on a canvas, ``auto``'s engine (from the
pixels around the hole in a run; from the inputs' shapes alone for the studio, which shows it), and
the edge guide whose edges decide between ``patchmatch`` and ``hybrid``.
"""

from __future__ import annotations

from collections.abc import Mapping

import cv2
import numpy as np

from ..errors import WeftError
from ..geometry import Margins
from .common import neighbourhood, touches_border, whole_patches
from .inputs import _margins
from .params import BORDER_BLOCK, DEFAULT_PATCH, FillParams, auto_engine
from .quilt import is_colour


def _run_patch(
    params: FillParams, ch: int, cw: int, *, hole: np.ndarray | None = None, margins: Margins | None = None
) -> int:
    """The patch side a run of ``params.engine`` (not ``auto``) uses on a ``cw`` x ``ch`` canvas: the
    one given, or the engine's default fitted to a small canvas; the quilt's :data:`BORDER_BLOCK`
    (at most a third of the canvas) for a hole along the border deeper than its 24-px block
    (:func:`_deep_border`, of the canvas's ``hole``, or of the ``margins`` when only shapes are known)."""
    patch = params.resolved_patch()
    if params.patch is None and params.engine == "quilt" and _deep_border(hole, margins):
        patch = max(patch, min(BORDER_BLOCK, min(ch, cw) // 3))
    if params.patch is None and patch > min(ch, cw) // 2:  # a default patch fits a small image
        patch = max(3, min(ch, cw) // 2)
    if params.patch is None and params.engine == "hybrid":  # its large block: at most a third of a small image
        patch = min(patch, max(3, min(ch, cw) // 3))
    return patch


def _deep_border(hole: np.ndarray | None, margins: Margins | None) -> bool:
    """Whether the hole runs along the canvas border and reaches more than the quilt's default block
    (24 px) from the known pixels: an uncrop or an extended canvas, whose quilt takes
    :data:`BORDER_BLOCK`; a small hole that touches the border keeps 24. Of ``hole`` when given (a
    chessboard distance, so that margins of L, T, R, B reach their largest), else of ``margins``."""
    if hole is None:
        return margins is not None and max(margins) > DEFAULT_PATCH["quilt"]
    if not touches_border(hole):
        return False
    d = cv2.distanceTransform(hole.astype(np.uint8), cv2.DIST_C, 3)
    return float(d.max()) > DEFAULT_PATCH["quilt"]


def _largest_square(region: np.ndarray) -> int:
    """The side of the largest square inside ``region`` (0 if empty), from a chessboard distance."""
    if not region.any():
        return 0
    d = cv2.distanceTransform(np.pad(region, 1).astype(np.uint8), cv2.DIST_C, 3)
    r = int(d.max())
    return 2 * r if whole_patches(region, 2 * r).any() else 2 * r - 1


def _resolve_auto(
    params: FillParams, colour: np.ndarray, hole: np.ndarray, transparent: np.ndarray, has_texture: bool
) -> tuple[FillParams, tuple[tuple[slice, slice], np.ndarray | None, int] | None]:
    """``(params, edge guide)``: ``params`` with ``auto``'s engine resolved on this canvas, so that the
    figures and messages name the engine that runs, and the edge guide worked out on the way
    (:func:`_edge_guide`'s ``(part, guide, edges continued)``, for the run to take) or None.
    ``params`` as they are when they name an engine."""
    if params.engine != "auto":
        return params, None
    ch, cw = hole.shape
    # decided on the hole's neighbourhood, the part the engine fills when the hole is small in a
    # large picture (a colour corner far from a hole in a grey region does not make it a photo)
    known = ~hole & ~transparent
    near = neighbourhood(hole, known, DEFAULT_PATCH["quilt"]) or (slice(None), slice(None))
    picture = colour.ndim == 3 and is_colour(colour[near], known[near])
    on_border = touches_border(hole)
    edges = None
    pending = None
    if (
        not has_texture
        and params.structure == "auto"
        and auto_engine(picture, on_border, params.patch, params.structure, True) == "patchmatch"
    ):
        # whether the edge guide finds edges to continue decides; on the part patchmatch would
        # fill, so that its run takes this guide
        pending = _edge_guide(colour, hole, transparent, params.replace(engine="patchmatch"), ch, cw)
        edges = pending[2] > 0
    return params.replace(engine=auto_engine(picture, on_border, params.patch, params.structure, edges)), pending


def _edge_guide(
    colour: np.ndarray, hole: np.ndarray, transparent: np.ndarray, params: FillParams, ch: int, cw: int
) -> tuple[tuple[slice, slice], np.ndarray | None, int]:
    """``(part, guide, edges continued)``: the structure guide of ``hole`` on the part of the canvas a
    run of ``params.engine`` fills (:func:`neighbourhood` of its patch; the whole canvas when that is
    most of it), from the known pixels that are not transparent."""
    from .structure import structure_guide

    known = ~hole & ~transparent
    near = neighbourhood(hole, known, _run_patch(params, ch, cw, hole=hole))
    part = (slice(None), slice(None)) if near is None else near
    guide, n = structure_guide(colour[part], hole[part], known[part])
    return part, guide, n


def engine_text(params: FillParams) -> str:
    """The words naming the engine a fill runs with.

    Parameters
    ----------
    params : FillParams
        The fill's parameters.

    Returns
    -------
    str
    """
    return f"{params.engine} engine"


def _auto(params: FillParams, shapes: Mapping[str, tuple]) -> dict:
    """What an unset ``patch`` resolves to with inputs of these shapes (the studio shows it beside its
    box, and the variations grid centres its range on it): the patch the run takes (the engine's
    default, fitted to a small canvas; the quilt's border block for margins over 24 px). Nothing when
    the run decides it from the pixels, which a shape does not tell: ``auto``'s engine on a colour
    picture with a painted hole (:func:`auto_engine`: patchmatch where the edge guide pairs edges
    across it); the result's figures then say what ran. Nothing before an image is open."""
    shape = shapes.get("image")
    if params.patch is not None or shape is None:
        return {}
    h, w = shape[:2]
    try:
        margins = _margins(params, w, h)
    except WeftError:
        return {}
    if margins is not None:
        h, w = h + margins.top + margins.bottom, w + margins.left + margins.right
    if params.engine == "auto":
        colour = len(shape) == 3 and shape[2] >= 3
        painted = shapes.get("mask") is not None or (len(shape) == 3 and shape[2] in (2, 4))
        if params.structure == "auto" and colour and painted:
            return {}  # patchmatch or hybrid, as the edge guide finds edges in the hole or not
        params = params.replace(engine=auto_engine(colour, margins is not None, None, params.structure))
    return {"patch": _run_patch(params, h, w, margins=margins)}
