"""The method dock: the method list, its parameters, the seed, and the render/compare/variations buttons.

Contract
--------
* Built from ``weft.core.registry.studio_methods()`` and the current method's ``Params`` specs and studio
  description; it names no method, input or parameter.
* It changes the document only through its setters (``set_method``, ``set_param``, ``set_seed``; a
  slider held is ``drag_param``, let go ``set_param``: the renderer decides what to render) and
  shows the document after each change through :meth:`show_method`, :meth:`show_params`,
  :meth:`show_seed`, :meth:`show_square`.
* Signals: ``render_requested()``; ``variations_requested()``; ``message(text)`` a one-line problem.
  ``compare_button`` is checkable (the window connects it to the result view).
"""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import Qt, Signal
from PySide6.QtGui import QPixmap
from PySide6.QtWidgets import (
    QComboBox,
    QHBoxLayout,
    QLabel,
    QPushButton,
    QScrollArea,
    QSpinBox,
    QToolButton,
    QVBoxLayout,
    QWidget,
)
from weft.core.errors import WeftError
from weft.core.geometry import Square
from weft.core.params import FLOAT, INT
from weft.core.studio import SQUARE

from .convert import to_qimage
from .params_panel import ParamsPanel

THUMB = 96


class MethodPanel(QWidget):
    """See the module docstring."""

    render_requested = Signal()
    variations_requested = Signal()
    message = Signal(str)

    def __init__(self, doc, parent=None):
        super().__init__(parent)
        self.doc = doc
        lay = QVBoxLayout(self)
        lay.addLayout(self._method_row())
        self.params_panel = ParamsPanel()
        self.params_panel.edited.connect(self._param_edited)
        scroll = QScrollArea()
        scroll.setWidgetResizable(True)
        scroll.setWidget(self.params_panel)
        lay.addWidget(scroll, 1)
        lay.addLayout(self._seed_row())
        lay.addWidget(self._square_row())
        lay.addLayout(self._buttons())

    def _method_row(self) -> QHBoxLayout:
        doc = self.doc
        top = QHBoxLayout()
        top.addWidget(QLabel("Method"))
        self.method_box = QComboBox()
        for name, method in doc.methods.items():
            self.method_box.addItem(method.studio.title, name)
            self.method_box.setItemData(
                self.method_box.count() - 1, f"weft {name}: {method.summary}", Qt.ItemDataRole.ToolTipRole
            )
        self.method_box.currentIndexChanged.connect(self._method_chosen)
        top.addWidget(self.method_box, 1)
        return top

    def _seed_row(self) -> QHBoxLayout:
        """The seed, New, and the thumbnail of the method's square with its caption."""
        self.square_label = QLabel()
        self.square_label.setFixedSize(THUMB, THUMB)
        self.square_label.setToolTip("the square drawn on the input (drag one on its view)")
        self.square_label.setStyleSheet("border:1px solid #888;")
        seed_row = QHBoxLayout()
        seed_row.addWidget(QLabel("seed"))
        self.seed_box = QSpinBox()
        self.seed_box.setRange(0, 2**31 - 1)
        self.seed_box.setValue(self.doc.seed)
        self.seed_box.setKeyboardTracking(False)
        self.seed_box.valueChanged.connect(lambda value: self.doc.set_seed(int(value)))
        seed_row.addWidget(self.seed_box, 1)
        new_seed = QToolButton()
        new_seed.setText("New")
        new_seed.setToolTip("a new random seed")
        new_seed.clicked.connect(self.new_seed)
        seed_row.addWidget(new_seed)
        square_box = QVBoxLayout()
        square_box.setSpacing(2)
        square_box.addWidget(self.square_label)
        self.square_caption = QLabel("")  # what the thumbnail is: the method's square, named
        self.square_caption.setAlignment(Qt.AlignmentFlag.AlignCenter)
        self.square_caption.setFixedWidth(THUMB)
        self.square_caption.setWordWrap(True)
        square_box.addWidget(self.square_caption)
        seed_row.addLayout(square_box)
        return seed_row

    def _square_row(self) -> QWidget:
        """The square typed: its corner and side (the same undoable edit as a drag on its view)."""
        self.square_row = QWidget()
        sq = QHBoxLayout(self.square_row)
        sq.setContentsMargins(0, 0, 0, 0)
        self.square_boxes: list[QSpinBox] = []
        for text, tip in (
            ("X", "left edge of the square, pixels from the image's left"),
            ("Y", "top edge of the square, pixels from the image's top"),
            ("side", "side of the square, pixels"),
        ):
            label = QLabel(text)
            box = QSpinBox()
            box.setKeyboardTracking(False)  # a typed number counts on Enter (or leaving the box)
            box.setToolTip(tip + "; Enter applies (Ctrl+Z undoes)")
            box.valueChanged.connect(self._square_typed)
            label.setBuddy(box)
            sq.addWidget(label)
            sq.addWidget(box, 1)
            self.square_boxes.append(box)
        return self.square_row

    def _buttons(self) -> QHBoxLayout:
        buttons = QHBoxLayout()
        self.render_button = QPushButton("Render")
        self.render_button.setToolTip("render the full-size result (F5)")
        self.render_button.clicked.connect(self.render_requested)
        self.compare_button = QPushButton("Compare")
        self.compare_button.setCheckable(True)
        self.compare_button.setToolTip("before/after split on the result: drag to move the divider (C)")
        self.variations_button = QPushButton("Variations…")
        self.variations_button.setToolTip("render a grid over two parameters and adopt a cell")
        self.variations_button.clicked.connect(self.variations_requested)
        for b in (self.render_button, self.compare_button, self.variations_button):
            buttons.addWidget(b)
        return buttons

    # --- user edits ----------------------------------------------------------------------------
    def _method_chosen(self, index: int) -> None:
        name = self.method_box.itemData(index)
        if name:
            self.doc.set_method(name)

    def _param_edited(self, name: str, value, dragging: bool) -> None:
        try:
            if dragging:
                self.doc.drag_param(name, value)
            else:
                # a slider's moves are one undo step; a choice from a list, a switch or a typed size is its own
                row = self.params_panel.rows.get(name)
                self.doc.set_param(name, value, merge=row is not None and row.spec.kind in (INT, FLOAT))
        except WeftError as e:
            self.message.emit(str(e))
            self.show_params()  # back to the valid value

    def _square_typed(self, _value=None) -> None:
        """X, Y or side typed: the square they give, checked as the CLI checks ``--region X,Y,S`` /
        ``--prototype`` (the corner, the side, inside the image, the method's own rules), becomes
        the document's square; a refused one is said in one line and the boxes show the square there is."""
        doc = self.doc
        g = doc.geometry_of(SQUARE)
        if g is None:
            return
        where = g.input_for(doc.inputs)
        image = doc.image(where)
        if image is None:
            return
        values = [b.value() for b in self.square_boxes]
        if doc.value(g.key) is None:  # none drawn: the boxes left blank take the corner and a default side
            values = [
                d if v == b.minimum() else v
                for v, b, d in zip(values, self.square_boxes, _default_square(image), strict=True)
            ]
        try:
            square = Square.parse(values, g.key)
            square.crop(image, where.replace("_", " "), g.key)
            if g.param is not None:
                doc.current_params.replace(**{g.param: square})  # the method's rules (e.g. an even side)
        except WeftError as e:
            self.message.emit(str(e))
            self.show_square()
            return
        doc.set_geometry(g.key, square, "Square")

    def new_seed(self) -> None:
        self.seed_box.setValue(int(np.random.default_rng().integers(0, 2**31 - 1)))

    # --- showing the document ------------------------------------------------------------------
    def show_method(self) -> None:
        """The current method: its entry in the list and its parameter editors (geometry parameters
        are edited with the mouse on the inputs, not here)."""
        doc = self.doc
        self.method_box.blockSignals(True)
        self.method_box.setCurrentIndex(self.method_box.findData(doc.method))
        self.method_box.blockSignals(False)
        hidden = tuple(g.param for g in doc.studio.geometry if g.param is not None)
        self.params_panel.build(doc.current.params, hidden=hidden)
        self.show_params()
        self.show_square()

    def show_params(self) -> None:
        """The current parameters, each unset ("auto") one with the value a run resolves it to."""
        self.params_panel.show_params(self.doc.current_params, self.doc.auto_values(), self.doc.param_ranges())

    def show_seed(self) -> None:
        self.seed_box.blockSignals(True)
        self.seed_box.setValue(self.doc.seed)
        self.seed_box.blockSignals(False)

    def show_square(self, square=None) -> None:
        """The thumbnail of the current method's square (``square`` while it is dragged)."""
        doc = self.doc
        g = doc.geometry_of(SQUARE)
        if g is not None and square is None:
            square = doc.value(g.key)
        image = None if g is None else doc.image(g.input_for(doc.inputs))
        self.square_label.setVisible(g is not None)
        self.square_caption.setVisible(g is not None)
        if g is not None:
            what = g.param.replace("_", " ") if g.param is not None else "source region"
            self.square_caption.setText(f"{what}: none drawn" if square is None else f"{what} {square[2]} px")
        self._show_square_boxes(g, square, image)
        if square is None or image is None:
            self.square_label.clear()
            return
        x, y, s = square
        patch = image[y : y + s, x : x + s]
        if patch.size:
            pix = QPixmap.fromImage(to_qimage(patch)).scaled(THUMB, THUMB, Qt.AspectRatioMode.KeepAspectRatio)
            self.square_label.setPixmap(pix)

    def _show_square_boxes(self, g, square, image) -> None:
        """The X, Y and side boxes: the square's values (blank when none is drawn), ranged to the
        image; hidden for a method with no square."""
        self.square_row.setVisible(g is not None)
        self.square_row.setEnabled(image is not None)
        if g is None or image is None:
            return
        h, w = image.shape[:2]
        limits = ((0, max(w - Square.MIN_SIDE, 0)), (0, max(h - Square.MIN_SIDE, 0)), (Square.MIN_SIDE, min(w, h)))
        for i, (box, (lo, hi)) in enumerate(zip(self.square_boxes, limits, strict=True)):
            box.blockSignals(True)
            if square is None:  # blank (the minimum shows "–") until a number is typed
                box.setRange(lo - 1, max(lo, hi))
                box.setSpecialValueText("–")
                box.setValue(lo - 1)
            else:
                box.setSpecialValueText("")
                box.setRange(lo, max(lo, hi))
                box.setValue(int(square[i]))
            box.blockSignals(False)


def _default_square(image) -> tuple[int, int, int]:
    """What a typed square takes for the numbers left blank: the top-left corner and an even side of
    half the image's shorter side."""
    side = max(Square.MIN_SIDE, min(image.shape[:2]) // 2)
    return 0, 0, side - side % 2
