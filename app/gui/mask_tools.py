"""The tools of painted masks and of an uncrop's margins (DESIGN.md, Studio and Geometry), one file each:

* :mod:`.mask_overlay` -- a mask drawn over its image in a translucent colour of its own;
* :mod:`.mask_tool` -- the brush, eraser and lasso of one mask (``Geometry(MASK, input=...)``),
  Include / Exclude for a mask whose absence means every pixel (``Geometry.empty_is_all``), the
  brush sized to the picture;
* :mod:`.margins_tool` -- dragging the canvas edges outward (``Geometry(MARGINS, param=...)``) and
  "Extend canvas…";
* :mod:`.tool_set` -- several tools on one view (the masks of an image, the margins), and the rule
  that decides which takes a press;
* :mod:`.geometry_bar` -- the buttons over such a view: which mask the brush paints, the modes, the
  brush size, Clear, Invert, Fill transparent, Extend canvas….

This module gathers them for the inputs pane.
"""

from .geometry_bar import GeometryBar
from .margins_tool import ExtendDialog, MarginsTool
from .mask_overlay import MASK_COLOURS, MASK_RGBA, MaskOverlay
from .mask_tool import (
    BRUSH,
    BRUSH_DEFAULT,
    BRUSH_MAX,
    BRUSH_MIN,
    ERASER,
    LASSO_ADD,
    LASSO_SUBTRACT,
    MODES,
    MaskTool,
    default_size,
)
from .tool_set import ToolSet

__all__ = [
    "GeometryBar",
    "ExtendDialog",
    "MarginsTool",
    "MASK_COLOURS",
    "MASK_RGBA",
    "MaskOverlay",
    "BRUSH",
    "BRUSH_DEFAULT",
    "BRUSH_MAX",
    "BRUSH_MIN",
    "ERASER",
    "LASSO_ADD",
    "LASSO_SUBTRACT",
    "MODES",
    "MaskTool",
    "default_size",
    "ToolSet",
]
