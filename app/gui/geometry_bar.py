"""The buttons over a view whose image carries painted masks or an uncrop's margins.

The buttons wrap onto as many rows as the pane's width needs (:class:`~.flow_layout.FlowLayout`), so
every one shows (a 1024 px window included), none behind a toolbar's overflow menu; in groups:

* what is painted and how: when the image carries several masks, a switch between them (a hole, a
  sampling area: ``Geometry.label``), then Brush, Eraser, Lasso +, Lasso − (for a mask whose absence
  means "every pixel", ``Geometry.empty_is_all``, read as Include, Exclude, Lasso +, Lasso −);
* the brush size (and the actions "Smaller brush" ``[`` and "Larger brush" ``]``, shortcuts of the
  whole window while the mask tool is shown; a text field with the focus keeps them as text), Clear,
  Invert, Fill transparent, Extend canvas….

Clear and Invert act on the mask being painted; Fill transparent makes the first mask that is no
"every pixel" mask (a hole) the image's transparent pixels.
"""

from __future__ import annotations

from PySide6.QtCore import Qt, Signal
from PySide6.QtGui import QAction, QActionGroup, QKeySequence
from PySide6.QtWidgets import QFrame, QSizePolicy, QSpinBox, QToolButton, QWidget
from weft.core.geometry import Mask

from .flow_layout import FlowLayout
from .margins_tool import ExtendDialog, MarginsTool
from .mask_tool import BRUSH, BRUSH_MAX, BRUSH_MIN, ERASER, LASSO_ADD, LASSO_SUBTRACT, MODES, MaskTool

_EDGES = (
    "; outside the image a press paints while the brush's circle covers the image, and drags the canvas "
    "edges farther out or with Shift"
)
_LABELS = {BRUSH: "Brush", ERASER: "Eraser", LASSO_ADD: "Lasso +", LASSO_SUBTRACT: "Lasso −"}
_LABELS_ALL = {BRUSH: "Include", ERASER: "Exclude", LASSO_ADD: "Lasso +", LASSO_SUBTRACT: "Lasso −"}


def _tips(name: str, everywhere: bool) -> dict[str, str]:
    """The mode buttons' tooltips for a mask called ``name``."""
    if everywhere:
        return {
            BRUSH: f"Include: paint the {name}, where the method may copy from (on nothing painted: only "
            f"there; [ and ] size the brush)" + _EDGES,
            ERASER: f"Exclude: paint where the method must not copy from (on nothing painted: everywhere "
            f"else stays in the {name})" + _EDGES,
            LASSO_ADD: f"draw a closed outline to add to the {name}",
            LASSO_SUBTRACT: f"draw a closed outline to take from the {name}",
        }
    return {
        BRUSH: f"paint the {name} ([ and ] size the brush; Esc cancels a stroke)" + _EDGES,
        ERASER: f"erase the {name} ([ and ] size the brush)" + _EDGES,
        LASSO_ADD: f"draw a closed outline to add to the {name} (start it inside the image: a press "
        "outside drags the canvas edges)",
        LASSO_SUBTRACT: f"draw a closed outline to take from the {name} (start it inside the image: a "
        "press outside drags the canvas edges)",
    }


def _separator() -> QFrame:
    line = QFrame()
    line.setFrameShape(QFrame.Shape.VLine)
    line.setFrameShadow(QFrame.Shadow.Sunken)
    line.setFixedSize(7, 20)
    return line


class GeometryBar(QWidget):
    """The buttons of a view's mask and margins tools (module docstring). ``message(text)``: a
    one-line note (why an action did nothing, what the mask switched to means)."""

    message = Signal(str)

    def __init__(self, doc, parent=None):
        super().__init__(parent)
        self.doc = doc
        self.mask_tool: MaskTool | None = None  # the armed one: what the brush paints
        self.mask_tools: list[MaskTool] = []
        self.margins_tool: MarginsTool | None = None
        self.setSizePolicy(QSizePolicy.Policy.Ignored, QSizePolicy.Policy.Preferred)
        self.flow = FlowLayout(self)
        # which mask the brush paints (shown when the image carries several)
        self.target_group = QActionGroup(self)
        self.target_actions: list[QAction] = []
        self.target_buttons: list[QToolButton] = []
        self.target_separator = _separator()
        self.flow.addWidget(self.target_separator)
        self.mode_group = QActionGroup(self)
        self.mode_actions: dict[str, QAction] = {}
        self.mode_buttons: dict[str, QToolButton] = {}
        for mode in MODES:
            action = QAction(_LABELS[mode], self)  # owned by the bar (the window's menu shows them too)
            action.setCheckable(True)
            self.mode_group.addAction(action)
            self.mode_actions[mode] = action
            self.mode_buttons[mode] = self._button(action)
            action.toggled.connect(lambda on, m=mode: on and self.mask_tool is not None and self.mask_tool.set_mode(m))
        self._label_modes(None)
        self.size_box = QSpinBox()
        self.size_box.setRange(BRUSH_MIN, BRUSH_MAX)
        self.size_box.setSuffix(" px")
        self.size_box.setToolTip("brush size in image pixels ([ smaller, ] larger)")
        self.size_box.valueChanged.connect(lambda v: self.mask_tool is not None and self.mask_tool.set_size(v))
        self.edit_separator = _separator()
        self.flow.addWidget(self.edit_separator)
        self.flow.addWidget(self.size_box)
        self.size_action = self.size_box  # (shown and hidden with the mask tool, as the actions are)
        # [ and ]: shortcuts of the window while the size box is shown (the mask tool is), whatever has
        # the focus -- a button or slider just clicked too; a text field keeps them (Qt gives a key a
        # focused text field types to the field, not to a shortcut). Actions of the size box, not
        # buttons of the bar; the window's Edit > Mask and Canvas menu lists them.
        self.smaller_action = self._brush_action("Smaller brush", "[", -1)
        self.larger_action = self._brush_action("Larger brush", "]", +1)
        self.clear_action = self._action("Clear", "", self.clear_mask)
        self.invert_action = self._action("Invert", "", self.invert_mask)
        self.transparent_action = self._action("Fill transparent", "", self.fill_transparent)
        self.extend_action = self._action(
            "Extend canvas…",
            "type the pixels to add on each side (or drag outward "
            "from outside the image: beyond the brush's circle, or with Shift)",
            self.extend_dialog,
        )
        self.clear_button, self.invert_button, self.transparent_button, self.extend_button = (
            self.buttons[a]
            for a in (self.clear_action, self.invert_action, self.transparent_action, self.extend_action)
        )

    def _button(self, action: QAction, index: int | None = None) -> QToolButton:
        """A button for ``action`` in the flow (at ``index``, else last), shown while it is visible."""
        button = QToolButton(self)
        button.setDefaultAction(action)
        button.setAutoRaise(True)
        button.setToolButtonStyle(Qt.ToolButtonStyle.ToolButtonTextOnly)
        if index is None:
            self.flow.addWidget(button)
        else:
            self.flow.insertWidget(index, button)
        self.buttons = getattr(self, "buttons", {})
        self.buttons[action] = button
        action.changed.connect(lambda b=button, a=action: b.setVisible(a.isVisible()))
        return button

    def _brush_action(self, text: str, key: str, steps: int) -> QAction:
        action = QAction(text, self.size_box)
        action.setShortcut(QKeySequence(key))
        action.setShortcutContext(Qt.ShortcutContext.WindowShortcut)
        action.setToolTip(f"{text.lower()} ({key})")
        action.triggered.connect(lambda _=False: self.mask_tool is not None and self.mask_tool.grow(steps))
        self.size_box.addAction(action)
        return action

    def _action(self, text, tip, slot) -> QAction:
        action = QAction(text, self)
        self._button(action)
        action.setToolTip(tip)
        action.triggered.connect(lambda _=False: slot())
        return action

    def menu_actions(self) -> list[QAction]:
        """Its actions that apply now (for the window's Edit menu)."""
        return [
            a
            for a in (
                *self.target_actions,
                *self.mode_actions.values(),
                self.smaller_action,
                self.larger_action,
                self.clear_action,
                self.invert_action,
                self.transparent_action,
                self.extend_action,
            )
            if a.isVisible()
        ]

    # --- which tools -----------------------------------------------------------------------------
    def attach(self, mask_tool, margins_tool: MarginsTool | None) -> None:
        """Show the buttons of these tools: ``mask_tool`` one mask tool, or a list of the image's
        (a switch chooses which one paints), or None; a view with neither hides the bar."""
        tools = [] if mask_tool is None else list(mask_tool) if isinstance(mask_tool, (list, tuple)) else [mask_tool]
        if tools != self.mask_tools:
            self._make_targets(tools)
        self.mask_tools, self.margins_tool = tools, margins_tool
        armed = next((t for t in tools if t.armed), tools[0] if tools else None)
        has_mask = armed is not None
        for a in [
            *self.mode_actions.values(),
            self.size_action,
            self.smaller_action,
            self.larger_action,
            self.clear_action,
            self.invert_action,
            self.transparent_action,
            self.edit_separator,
        ]:
            a.setVisible(has_mask)
        self.transparent_action.setVisible(any(not t.everywhere for t in tools))
        self.extend_action.setVisible(margins_tool is not None)
        for tool in tools:
            tool.on_size = self._show_size
        self.mask_tool = None
        if has_mask:
            self.arm(armed, say=False)
        self.setVisible(has_mask or margins_tool is not None)
        self.refresh()

    def _make_targets(self, tools: list[MaskTool]) -> None:
        for action, button in zip(self.target_actions, self.target_buttons, strict=True):
            self.target_group.removeAction(action)
            self.flow.removeWidget(button)
            self.buttons.pop(action, None)
            button.deleteLater()
            action.deleteLater()
        self.target_actions, self.target_buttons = [], []
        if len(tools) > 1:
            for i, tool in enumerate(tools):
                action = QAction(tool.name[:1].upper() + tool.name[1:], self)
                action.setCheckable(True)
                action.setToolTip(f"the brush paints the {tool.name}")
                action.toggled.connect(lambda on, t=tool: on and self.arm(t))
                self.target_group.addAction(action)
                self.target_actions.append(action)
                self.target_buttons.append(self._button(action, index=i))
        self.target_separator.setVisible(len(tools) > 1)

    def target_button(self, index: int) -> QToolButton:
        """The switch's button for the image's ``index``-th mask."""
        return self.target_buttons[index]

    def arm(self, tool: MaskTool, *, say: bool = True) -> None:
        """The brush paints ``tool``'s mask from now on (its mode and size shown)."""
        if tool is self.mask_tool and tool.armed:
            return
        for other in self.mask_tools:
            if other is not tool:
                other.disarm()
        tool.armed = True
        self.mask_tool = tool
        if tool in self.mask_tools and self.target_actions:
            action = self.target_actions[self.mask_tools.index(tool)]
            if not action.isChecked():
                action.setChecked(True)
        self._label_modes(tool)
        self.mode_actions[tool.mode].setChecked(True)
        self._show_size(tool.size)
        self.refresh()
        if say:
            self.message.emit(self.describe(tool))

    def describe(self, tool: MaskTool) -> str:
        """What painting ``tool``'s mask does now, in one line."""
        if not tool.everywhere:
            return f"the brush paints the {tool.name}"
        if tool.mask() is None:
            others = [t.name for t in self.mask_tools if t is not tool]
            outside = f"outside the {others[0]}" if others else ""
            return (
                f"the brush paints the {tool.name}: nothing painted yet, so everywhere {outside} — Include "
                f"to copy only from where you paint, Exclude to keep copies away from there"
            ).replace("  ", " ")
        return f"the brush paints the {tool.name} (shown in its own colour): Include adds to it, Exclude takes away"

    def _label_modes(self, tool: MaskTool | None) -> None:
        everywhere = tool is not None and tool.everywhere
        labels = _LABELS_ALL if everywhere else _LABELS
        tips = _tips("painted area" if tool is None else tool.name, everywhere)
        for mode, action in self.mode_actions.items():
            action.setText(labels[mode])
            action.setToolTip(tips[mode])

    def _show_size(self, size: int) -> None:
        if self.mask_tool is not None and self.mask_tool.size != size:
            return  # another mask's tool (sized to the picture): not the brush shown
        if self.size_box.value() != size:
            self.size_box.blockSignals(True)
            self.size_box.setValue(size)
            self.size_box.blockSignals(False)

    def _on_image(self) -> tuple[str, object | None]:
        on = self.mask_tool.geometry.input_for(self.doc.inputs)
        return on, self.doc.item(on)

    def _hole_tool(self) -> MaskTool | None:
        return next((t for t in self.mask_tools if not t.everywhere), None)

    def refresh(self) -> None:
        """Enable the actions that can do something now (a disabled one says why in its tooltip)."""
        if self.mask_tool is None:
            return
        tool = self.mask_tool
        on, item = self._on_image()
        pretty = on.replace("_", " ")
        mask = tool.mask()
        self.clear_action.setEnabled(mask is not None and bool(mask))
        self.clear_action.setToolTip(
            f"remove the whole {tool.name}"
            + (" (then the method copies from everywhere again)" if tool.everywhere else "")
        )
        self.invert_action.setEnabled(item is not None and not (tool.everywhere and mask is None))
        self.invert_action.setToolTip(
            f"nothing painted: the {tool.name} is everywhere already"
            if tool.everywhere and mask is None
            else f"swap what the {tool.name} covers and what it does not"
        )
        hole = self._hole_tool()
        alpha = None if item is None else item.alpha
        if item is None:
            why = f"no {pretty} is open"
        elif alpha is None:
            why = f"the {pretty} has no alpha channel: nothing is transparent"
        elif not (alpha < 0.5).any():
            why = f"the {pretty} has an alpha channel but no transparent pixel"
        else:
            why = ""
        self.transparent_action.setEnabled(not why and hole is not None)
        self.transparent_action.setToolTip(
            why or f"make the {hole.name if hole else ''} the transparent pixels of the {pretty}"
        )

    # --- the actions -----------------------------------------------------------------------------
    def clear_mask(self) -> None:
        if self.mask_tool is not None and self.mask_tool.mask() is not None:
            self.doc.set_mask(self.mask_tool.geometry_key, None, f"Clear {self.mask_tool.name}")

    def invert_mask(self) -> None:
        tool = self.mask_tool
        if tool is None or self._on_image()[1] is None or (tool.everywhere and tool.mask() is None):
            return
        base = tool.base()
        inverted = Mask(~base.bits)
        if tool.everywhere and not inverted:
            self.message.emit(f"the {tool.name} cannot be empty: nothing would be left to copy from")
            return
        self.doc.set_mask(tool.geometry_key, inverted, f"Invert {tool.name}")

    def fill_transparent(self) -> None:
        tool = self._hole_tool()
        if tool is None:
            return
        on = tool.geometry.input_for(self.doc.inputs)
        item = self.doc.item(on)
        if item is None or item.alpha is None:
            self.message.emit(f"the {on.replace('_', ' ')} has no alpha channel: nothing is transparent")
            return
        self.doc.set_mask(tool.geometry_key, Mask.from_alpha(item.alpha), "Fill transparent")

    def extend_dialog(self) -> ExtendDialog | None:
        """Open the "Extend canvas" dialog (window-modal); OK sets the margins (one undo step)."""
        tool = self.margins_tool
        if tool is None:
            return None
        dialog = ExtendDialog(tool.margins(), tool.view.image_size(), self.window())
        dialog.setAttribute(Qt.WidgetAttribute.WA_DeleteOnClose)

        def apply() -> None:
            margins = dialog.margins()
            if margins != tool.margins():
                self.doc.set_margins(tool.geometry_key, margins, f"Extend canvas {margins.to_text()}")

        dialog.accepted.connect(apply)
        self.dialog = dialog  # (the open one: tests reach it)
        dialog.open()
        return dialog
