"""Typed geometry: a square, feature lines, a mask, margins, and how each is read and written at the edges.

A geometry value is parsed once where it enters weft -- command-line text (:meth:`parse`), the JSON
of a recipe or session (:meth:`from_json`), a Python caller's value (:meth:`coerce`) -- and is held
typed everywhere else: in a method's ``Params``, in the studio's document, in a result's recipe. It
is written once, by :meth:`to_json` (and :meth:`to_text` for a command line). Nothing is turned into
text and parsed again per render.

A ``Params`` field holds one with ``param(None, kind="geometry", type=Square)`` (see
:mod:`weft.core.params`); any class with these four methods (:class:`GeometryValue`) can be such a
type (:class:`weft.core.rectify.View` is one more).

Command-line rule for lines and views (one rule, stated here and in ``--help``): text that starts with
``{`` is the JSON object itself; anything else is the name of a JSON file.
"""

from . import interface as _interface
from .interface import KINDS, GeometryValue
from .lines import FeatureLines, LineDraft
from .margins import Margins
from .mask import Mask
from .raster import paint_line
from .reading import MAX_SIDE, as_lines, as_size, read_json_or_file, whole_number  # noqa: F401 (re-exported)
from .square import Square
from .stroke import MaskStroke

#: The kinds of geometry the studio has a tool for (a method's studio description names them per input):
#: a square (dragged), feature lines (drawn in pairs), a mask (painted with a brush, eraser or lasso)
#: and margins (the canvas's edges dragged outward: an uncrop).
SQUARE, LINES, MASK, MARGINS = _interface.SQUARE, _interface.LINES, _interface.MASK, _interface.MARGINS

# The value types are documented, pickled and imported under the package's name (saved pickles and
# the API pages name weft.core.geometry.Square, not the module that defines it).
for _cls in (GeometryValue, Square, FeatureLines, LineDraft, Mask, MaskStroke, Margins):
    _cls.__module__ = __name__
del _cls

__all__ = [
    "GeometryValue",
    "Square",
    "FeatureLines",
    "LineDraft",
    "Mask",
    "MaskStroke",
    "paint_line",
    "Margins",
    "read_json_or_file",
    "SQUARE",
    "LINES",
    "MASK",
    "MARGINS",
    "KINDS",
]
