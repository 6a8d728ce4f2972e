"""The parameter panel, generated from a method's ``Params`` specs (the CLI reads the same specs).

Numbers get labelled sliders with a typed entry (superqt), choices a combo box, switches a check
box, sizes two spin boxes; an optional parameter has an "auto" box (its value is then derived, see
the method's docs). Tooltips give the paper's symbol, the range and the help text; the ↺ button resets
to the default. ``edited(name, value, dragging)`` is emitted on every user change; ``dragging`` is
true while a slider is held down (the window renders a preview then, and the full result on release).
"""

from __future__ import annotations

from typing import Any

from PySide6.QtCore import Qt, Signal
from PySide6.QtWidgets import (
    QCheckBox,
    QComboBox,
    QFormLayout,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QSpinBox,
    QToolButton,
    QWidget,
)
from superqt import QLabeledDoubleSlider, QLabeledSlider
from weft.core.params import BOOL, CHOICE, FLOAT, INT, SIZE, Params, Spec, specs


def _fmt(v) -> str:
    return str(int(v)) if float(v).is_integer() else f"{float(v):g}"


class _Row(QWidget):
    """One parameter's editor."""

    changed = Signal(object, bool)  # value, dragging

    def __init__(self, spec: Spec, parent=None):
        super().__init__(parent)
        self.spec = spec
        lay = QHBoxLayout(self)
        lay.setContentsMargins(0, 0, 0, 0)
        self.auto: QCheckBox | None = None
        if spec.optional:
            self.auto = QCheckBox("auto")
            self.auto.setToolTip("derive the value from the inputs and mode (see the tooltip)")
            self.auto.toggled.connect(self._auto_toggled)
            lay.addWidget(self.auto)
        k = spec.kind
        if k in (INT, FLOAT):
            cls = QLabeledSlider if k == INT else QLabeledDoubleSlider
            self.editor = cls(Qt.Orientation.Horizontal)
            lo = spec.lo if spec.lo is not None else 0
            hi = spec.hi if spec.hi is not None else 100
            self.editor.setRange(lo, hi)
            if k == FLOAT:
                self.editor.setDecimals(3)
                self.editor.setSingleStep(spec.step or (hi - lo) / 100)
            elif spec.step:  # values on a grid (odd sides): keys and the wheel step along it
                self.editor.setSingleStep(int(spec.step))
                self.editor.setPageStep(int(spec.step))
            self._shown = self.editor.value()
            self.editor.valueChanged.connect(self._value_changed)
            self.editor.sliderReleased.connect(lambda: self.changed.emit(self.value(), False))
        elif k == CHOICE:
            self.editor = QComboBox()
            self.editor.addItems([str(c) for c in spec.choices])
            self.editor.currentTextChanged.connect(lambda _: self.changed.emit(self.value(), False))
        elif k == BOOL:
            self.editor = QCheckBox()
            self.editor.toggled.connect(lambda _: self.changed.emit(self.value(), False))
        elif k == SIZE:
            self.editor = QWidget()
            sl = QHBoxLayout(self.editor)
            sl.setContentsMargins(0, 0, 0, 0)
            self.w_box, self.h_box = QSpinBox(), QSpinBox()
            for box in (self.w_box, self.h_box):
                box.setRange(int(spec.lo or 1), int(spec.hi or 16384))
                box.setKeyboardTracking(False)
                box.valueChanged.connect(lambda _: self.changed.emit(self.value(), False))
                sl.addWidget(box)
            self.w_box.setValue(512)
            self.h_box.setValue(512)
        else:
            self.editor = QLineEdit()
            self.editor.editingFinished.connect(lambda: self.changed.emit(self.value(), False))
        lay.addWidget(self.editor, 1)
        self.reset = QToolButton()
        self.reset.setText("↺")
        self.reset.setToolTip(f"reset {spec.name} to its default")
        self.reset.clicked.connect(lambda: self.changed.emit(spec.default, False))
        lay.addWidget(self.reset)
        self._range: tuple | None = None  # the narrower range the inputs allow (set_range), or None
        self._set_tip()

    def _set_tip(self) -> None:
        spec, k = self.spec, self.spec.kind
        tip = [spec.help or spec.name]
        if spec.symbol:
            tip.insert(0, f"paper symbol: {spec.symbol}")
        if self._range is not None:
            lo, hi = (_fmt(v) for v in self._range)
            tip.append(f"range {lo}..{hi} for these inputs and settings ({spec.range_text()} in general)")
        elif spec.range_text():
            tip.append(("one of " if k == CHOICE else "range ") + spec.range_text())
        self.setToolTip("\n".join(tip))
        self._auto_tip()
        label = getattr(self, "label", None)
        if label is not None:
            label.setToolTip(self.toolTip())

    def set_range(self, bounds: tuple | None, value: Any = None) -> None:
        """A slider's range for the open inputs (``bounds`` within the Spec's; None: the Spec's). A
        value already set outside it widens it (shown as it is, never clamped: the render says why
        it fails)."""
        if self.spec.kind not in (INT, FLOAT):
            return
        spec = self.spec
        full = (spec.lo if spec.lo is not None else 0, spec.hi if spec.hi is not None else 100)
        lo, hi = full if bounds is None else bounds
        if value is not None:
            lo, hi = min(lo, value), max(hi, value)
        self._range = None if (lo, hi) == tuple(full) else (lo, hi)
        if (self.editor.minimum(), self.editor.maximum()) != (lo, hi):
            self.editor.blockSignals(True)
            try:
                self.editor.setRange(lo, hi)
                self._shown = self.editor.value()
            finally:
                self.editor.blockSignals(False)
        self._set_tip()

    def _auto_toggled(self, on: bool) -> None:
        # unticked: the editor already shows what "auto" resolved to (set_value), so the value
        # starts there, not at the range's minimum
        self.editor.setEnabled(not on)
        self.editor.setVisible(True)
        self._auto_tip()
        self.changed.emit(self.value(), False)

    def _auto_tip(self, resolved: Any = None) -> None:
        """While "auto" is ticked the editor is disabled: its tooltip says why and how to edit it."""
        if self.auto is not None and self.auto.isChecked():
            now = "" if resolved is None else f" (now {resolved})"
            self.editor.setToolTip(
                f'{self.spec.name} is derived from the inputs: "auto" is ticked{now}.\n'
                f'Untick "auto" to set it by hand, starting from this value.'
            )
        else:
            self.editor.setToolTip(self.toolTip())

    def _value_changed(self, v) -> None:
        if self.spec.kind == INT and self.spec.step:
            # a drag or a typed value between grid values lands on the next one the way it moved
            on = self.spec.on_grid(v, self.editor.minimum(), self.editor.maximum(), up=v > self._shown)
            if on != v:
                self.editor.blockSignals(True)
                self.editor.setValue(on)
                self.editor.blockSignals(False)
            self._shown = on
        if self.auto is not None and self.auto.isChecked():
            self.auto.blockSignals(True)
            self.auto.setChecked(False)
            self.auto.blockSignals(False)
            self.editor.setEnabled(True)
        self.changed.emit(self.value(), bool(self.editor.isSliderDown()))

    def value(self) -> Any:
        if self.auto is not None and self.auto.isChecked():
            return None
        k = self.spec.kind
        if k == INT:
            return int(self.editor.value())
        if k == FLOAT:
            return round(float(self.editor.value()), 6)
        if k == CHOICE:
            return self.spec.choices[self.editor.currentIndex()]
        if k == BOOL:
            return self.editor.isChecked()
        if k == SIZE:
            return (self.w_box.value(), self.h_box.value())
        return self.editor.text()

    def set_value(self, value: Any, shown_when_auto: Any = None) -> None:
        """Show ``value`` without emitting ``changed``."""
        widgets = (
            [self, self.editor]
            + ([self.auto] if self.auto else [])
            + ([self.w_box, self.h_box] if self.spec.kind == SIZE else [])
        )
        for w in widgets:
            w.blockSignals(True)
        try:
            if self.auto is not None:
                self.auto.setChecked(value is None)
                self.editor.setEnabled(value is not None)
                # "auto" with no known value: show no number rather than a misleading one
                self.editor.setVisible(value is not None or shown_when_auto is not None)
            self._auto_tip(shown_when_auto if value is None else None)
            if value is None:
                value = shown_when_auto
            if value is None:
                return
            k = self.spec.kind
            if k in (INT, FLOAT):
                self.editor.setValue(value)
                self._shown = self.editor.value()
            elif k == CHOICE:
                self.editor.setCurrentIndex(list(self.spec.choices).index(value))
            elif k == BOOL:
                self.editor.setChecked(bool(value))
            elif k == SIZE:
                self.w_box.setValue(int(value[0]))
                self.h_box.setValue(int(value[1]))
            else:
                # a typed geometry shows its command-line text (e.g. X,Y,S), which the spec parses back
                self.editor.setText(value.to_text() if hasattr(value, "to_text") else str(value))
        finally:
            for w in widgets:
                w.blockSignals(False)


class ParamsPanel(QWidget):
    """Editors for every parameter of one ``Params`` class."""

    edited = Signal(str, object, bool)  # name, value, dragging

    def __init__(self, parent=None):
        super().__init__(parent)
        self.form = QFormLayout(self)
        self.form.setFieldGrowthPolicy(QFormLayout.FieldGrowthPolicy.AllNonFixedFieldsGrow)
        self.rows: dict[str, _Row] = {}
        self.params_cls: type[Params] | None = None

    def build(self, params_cls: type[Params], hidden: tuple[str, ...] = ()) -> None:
        """(Re)build the editors for ``params_cls``; names in ``hidden`` are edited elsewhere."""
        while self.form.rowCount():
            self.form.removeRow(0)
        self.rows = {}
        self.params_cls = params_cls
        for spec in specs(params_cls):
            if spec.name in hidden:
                continue
            row = _Row(spec, self)
            row.changed.connect(lambda value, dragging, name=spec.name: self.edited.emit(name, value, dragging))
            label = QLabel(f"{spec.name} ({spec.symbol})" if spec.symbol and spec.symbol != spec.name else spec.name)
            label.setToolTip(row.toolTip())
            row.label = label
            self.form.addRow(label, row)
            self.rows[spec.name] = row

    def show_params(
        self, params: Params, auto_values: dict[str, Any] | None = None, ranges: dict[str, tuple] | None = None
    ) -> None:
        """Show ``params`` (``auto_values`` are what "auto" resolves to, shown greyed; ``ranges`` the
        narrower range a parameter accepts with the open inputs, for its slider and tooltip)."""
        auto_values, ranges = auto_values or {}, ranges or {}
        for name, row in self.rows.items():
            value = getattr(params, name)
            row.set_range(
                ranges.get(name), value if isinstance(value, (int, float)) and not isinstance(value, bool) else None
            )
            row.set_value(value, auto_values.get(name))

    def row(self, name: str) -> _Row:
        return self.rows[name]
