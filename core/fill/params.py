"""Parameters of ``weft fill`` (:class:`FillParams`) and the engines it can run."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from ..errors import InvalidParameter
from ..geometry import MAX_SIDE, Margins
from ..params import Params, param
from .engines import TABLE

#: Where the image goes on a larger ``--size`` canvas.
ANCHORS = ("center", "top-left", "top", "top-right", "left", "right", "bottom-left", "bottom", "bottom-right")


#: The engines `--engine` offers (:data:`weft.core.fill.engines.TABLE`), and ``auto``, which picks one
#: of them for the picture (:func:`auto_engine`).
ENGINES = ("auto", *TABLE)
#: The default engine.
DEFAULT_ENGINE = "auto"
#: Engines of earlier versions and what their recipes now run.
RETIRED = {"pixel": "auto"}
#: Each engine's patch side when ``patch`` is not given.
DEFAULT_PATCH = {name: e.patch for name, e in TABLE.items()}
#: The quilt's block when ``patch`` is not given and the hole runs along the canvas border more than
#: 24 px deep (an uncrop, an extended canvas, a rectification's wide transparent border): at most a
#: third of the canvas's smaller side. With 24-px blocks an extension a few blocks deep drifts from
#: the picture's structure block by block (bricks without joints).
BORDER_BLOCK = 48
#: ``structure``'s values (:mod:`weft.core.fill.structure`): the edges a hole cuts are continued
#: where ``auto``'s engine rule finds edges to pair across an interior hole of a colour picture
#: (``auto``, the default; it then runs ``patchmatch``), always (``yes``: ``auto`` then runs
#: ``patchmatch``) or never (``no``).
STRUCTURE = ("auto", "yes", "no")


@dataclass(frozen=True)
class FillParams(Params):
    """Parameters of ``weft fill``."""

    engine: str = param(
        DEFAULT_ENGINE,
        choices=ENGINES,
        help="auto: patchmatch with the edge guide where it finds edges crossing a hole inside a "
        "colour picture (always with --structure yes), else hybrid; "
        + "; ".join(f"{name}: {e.summary}" for name, e in TABLE.items()),
    )
    patch: int | None = param(
        None,
        kind="int",
        lo=3,
        hi=256,
        optional=True,
        help="patch side in pixels (quilt, hybrid: the block; patchmatch: at most 63); "
        "default per engine, smaller on a small image: "
        + ", ".join(f"{k} {v}" for k, v in DEFAULT_PATCH.items())
        + f" ({BORDER_BLOCK} for an uncrop more than 24 px deep)",
    )
    extend: Margins | None = param(
        None,
        kind="geometry",
        type=Margins,
        optional=True,
        help="uncrop: pixels added on the left, top, right and bottom, filled like the hole",
    )
    size: tuple[int, int] | None = param(
        None,
        kind="size",
        lo=1,
        hi=MAX_SIDE,
        optional=True,
        help="uncrop to this canvas size (at least the image's), the image placed by --anchor",
    )
    anchor: str = param("center", choices=ANCHORS, help="where the image sits on a --size canvas")
    band: int = param(
        2,
        lo=0,
        hi=32,
        help="how far around the hole, in pixels, known pixels may change so the fill meets them "
        "without a visible step (a Poisson band); 0 = they never change",
    )
    structure: str = param(
        "auto",
        choices=STRUCTURE,
        help="continue the strong edges that cross the hole (a rim, a horizon) along smooth "
        "curves, where patches alone run them on straight or drip; auto: whenever the "
        "patchmatch engine runs on the picture's own pixels (no --texture); yes: always "
        "(auto then runs patchmatch); no: never",
    )

    def check(self) -> None:
        if self.extend is not None and self.size is not None:
            raise InvalidParameter(
                "parameters 'extend' and 'size' cannot be given together (both set the canvas)",
                name="size",
                value=self.size,
            )
        if self.structure == "yes" and self.engine not in ("auto", "patchmatch"):
            raise InvalidParameter(
                f"parameter 'structure' = yes needs the patchmatch engine (or auto), not '{self.engine}'",
                name="structure",
                value=self.structure,
            )
        if (self.engine == "patchmatch" or self.structure == "yes") and self.patch is not None:
            from .patchmatch import MAX_PATCH

            if self.patch > MAX_PATCH:
                what = "for the patchmatch engine" if self.engine == "patchmatch" else "with 'structure' (patchmatch)"
                raise InvalidParameter(
                    f"parameter 'patch' = {self.patch} is outside 3..{MAX_PATCH} {what}", name="patch", value=self.patch
                )

    @classmethod
    def from_dict(cls, data, *, base=None) -> FillParams:
        """As :meth:`Params.from_dict`, ``structure`` read by :func:`structure_value` (recipes and
        sessions of the round in which it was an on/off switch wrote ``true`` / ``false``), and an
        engine since dropped (:data:`RETIRED`) read as the one that replaced it."""
        if isinstance(data, Mapping) and "structure" in data:
            data = {**data, "structure": structure_value(data["structure"])}
        if isinstance(data, Mapping) and data.get("engine") in RETIRED:  # a recipe of an engine since dropped
            data = {**data, "engine": RETIRED[data["engine"]]}
        return super().from_dict(data, base=base)

    def continues_edges(self, texture: bool = False) -> bool:
        """Whether the structure guide runs: ``yes``, or ``auto`` when the engine that runs (``auto``
        resolved first) is ``patchmatch`` and the hole is filled from the picture itself."""
        if self.structure == "yes":
            return True
        return self.structure == "auto" and self.engine == "patchmatch" and not texture

    def resolved_patch(self) -> int:
        """The patch side the engine runs with (``auto`` resolved first: :func:`auto_engine`)."""
        return self.patch if self.patch is not None else DEFAULT_PATCH[self.engine]


def structure_value(value):
    """``structure`` as given, but ``True`` / ``False`` read as ``yes`` / ``no``.

    Older recipes stored an on/off switch: a ``False`` recipe reproduces its pixels, a ``True`` one
    gets the guide as it is now (laying out the coarsest level only).

    Parameters
    ----------
    value : object
        The recipe's or the caller's value.

    Returns
    -------
    object
        ``"yes"``, ``"no"`` or ``value`` unchanged (validated by the parameter's spec).
    """
    if isinstance(value, (bool, np.bool_)):
        return "yes" if value else "no"
    return value


def auto_engine(
    colour_picture: bool, hole_on_border: bool, patch: int | None, structure: str = "auto", edges: bool | None = None
) -> str:
    """The engine ``auto`` runs.

    ``patchmatch`` with the edge guide where that guide has edges to continue, in a colour picture's
    hole that does not touch the border, with ``structure`` = auto and a ``patch`` that engine takes
    (none given, or at most its largest); ``patchmatch`` with ``structure`` = yes; else ``hybrid``
    (quilting, then full-resolution patch search). Patch search guided along the edges continues a rim
    or a horizon a removed object cut; the hybrid's blocks fill textures and structureless holes more
    coherently (``python -m benchmarks.fill_suite``).

    Parameters
    ----------
    colour_picture : bool
        The picture is in colour on its known pixels.
    hole_on_border : bool
        The hole touches the picture's border.
    patch : int or None
        The patch given.
    structure : {"auto", "yes", "no"}, default "auto"
        The edge guide's switch.
    edges : bool or None
        At least one pair of edges crossing the hole, as
        :func:`weft.core.fill.structure.structure_guide` pairs them; None (not looked for, e.g. when
        only the inputs' shapes are known) counts as none.

    Returns
    -------
    str
        ``"patchmatch"`` or ``"hybrid"``.
    """
    from .patchmatch import MAX_PATCH

    if structure == "yes":
        return "patchmatch"
    if (
        structure == "auto"
        and colour_picture
        and not hole_on_border
        and edges
        and (patch is None or patch <= MAX_PATCH)
    ):
        return "patchmatch"
    return "hybrid"
