"""The method dock: the method list, its parameters, the seed, and the render/compare/variations buttons.

Contract
--------
* Built from ``weft.core.registry.studio_methods()`` and the current method's ``Params`` specs and studio
  description; it names no method, input or parameter.
* It changes the document only through its setters (``set_method``, ``set_param``, ``set_seed``) and
  shows the document after each ``changed`` through :meth:`show_method`, :meth:`show_params`,
  :meth:`show_seed`, :meth:`show_square`.
* Signals: ``preview_requested()`` while a slider is held (the edit is already in the document),
  ``final_requested()`` when it is let go;
  ``render_requested()``; ``variations_requested()``; ``message(text)`` a one-line problem.
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
from weft.core.studio import SQUARE

from .convert import to_qimage
from .params_panel import ParamsPanel

THUMB = 96


class MethodPanel(QWidget):
    """See the module docstring."""

    preview_requested = Signal()
    final_requested = Signal()
    render_requested = Signal()
    variations_requested = Signal()
    message = Signal(str)

    def __init__(self, doc, parent=None):
        super().__init__(parent)
        self.doc = doc
        self.dragging = False  # a slider is held: the document's "params" change asks for no final render
        lay = QVBoxLayout(self)
        top = QHBoxLayout()
        top.addWidget(QLabel("Method"))
        self.method_box = QComboBox()
        for name, method in doc.methods.items():
            self.method_box.addItem(method.studio.title, name)
            self.method_box.setItemData(self.method_box.count() - 1, f"weft {name}: {method.summary}",
                                        Qt.ItemDataRole.ToolTipRole)
        self.method_box.currentIndexChanged.connect(self._method_chosen)
        top.addWidget(self.method_box, 1)
        lay.addLayout(top)
        self.params_panel = ParamsPanel()
        self.params_panel.edited.connect(self._param_edited)
        scroll = QScrollArea()
        scroll.setWidgetResizable(True)
        scroll.setWidget(self.params_panel)
        lay.addWidget(scroll, 1)
        self.square_label = QLabel()
        self.square_label.setFixedSize(THUMB, THUMB)
        self.square_label.setToolTip("the square drawn on the input (drag one on its view)")
        self.square_label.setStyleSheet("border:1px solid #888;")
        seed_row = QHBoxLayout()
        seed_row.addWidget(QLabel("seed"))
        self.seed_box = QSpinBox()
        self.seed_box.setRange(0, 2**31 - 1)
        self.seed_box.setValue(doc.seed)
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
        lay.addLayout(seed_row)
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
        lay.addLayout(buttons)

    # --- user edits ----------------------------------------------------------------------------
    def _method_chosen(self, index: int) -> None:
        name = self.method_box.itemData(index)
        if name:
            self.doc.set_method(name)

    def _param_edited(self, name: str, value, dragging: bool) -> None:
        try:
            self.dragging = dragging
            self.doc.set_param(name, value)
        except WeftError as e:
            self.message.emit(str(e))
            self.show_params()  # back to the valid value
            return
        finally:
            self.dragging = False
        if dragging:
            self.preview_requested.emit()
        else:
            self.final_requested.emit()  # a release on an unchanged value still asks for the full size

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
        doc = self.doc
        self.params_panel.show_params(doc.current_params, doc.studio.resolved(doc.current_params, doc.inputs))

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
        if square is None or image is None:
            self.square_label.clear()
            return
        x, y, s = square
        patch = image[y:y + s, x:x + s]
        if patch.size:
            pix = QPixmap.fromImage(to_qimage(patch)).scaled(THUMB, THUMB, Qt.AspectRatioMode.KeepAspectRatio)
            self.square_label.setPixmap(pix)
