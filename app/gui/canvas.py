"""The inputs pane: one view per input of the current method, each with the tool of its geometry.

Contract
--------
* Built from the document and the current method's studio description (``weft.core.studio``) only: the
  canvas input in the large view on top, the other inputs (and a lines tool's frontal frame) in tabs
  below. It knows no method, input or parameter by name.
* It reads the document and changes it only through the tools (``Document.set_geometry`` /
  ``set_lines`` on release). :meth:`rebuild` after a method change, :meth:`input_changed` after an
  input changed, :meth:`geometry_changed` after a geometry changed.
* Signals: ``message(text)`` a one-line problem; ``dragging(key, value)`` a square is being dragged
  (the window renders a live preview when the geometry asks for one); ``painting(key, mask, box)`` a
  mask stroke is being drawn (``box`` around its latest dab; ``mask`` None: the stroke was cancelled);
  ``open_requested(input, path)`` a file was dropped on an input's view.
* A view with several geometries (a mask and an uncrop's margins) gets a ``ToolSet`` of their tools;
  a view with a mask or margins tool gets a ``GeometryBar`` (brush, eraser, lasso, Clear, Invert,
  Fill transparent, Extend canvas…) over it. An input that is a mask geometry has no view of its own:
  it is painted over its image.
"""

from __future__ import annotations

from PySide6.QtCore import Qt, Signal
from PySide6.QtWidgets import (
    QHBoxLayout,
    QLabel,
    QSizePolicy,
    QSplitter,
    QStackedWidget,
    QTabWidget,
    QToolButton,
    QVBoxLayout,
    QWidget,
)
from weft.core.studio import LINES, MARGINS, MASK, SQUARE

from .lines_panel import FeatureLinesPanel
from .mask_tools import GeometryBar, MarginsTool, MaskTool, ToolSet
from .tools import PatchTool, QuadTool, Tool
from .views import ImageView


def titled(view: QWidget, title: str) -> QWidget:
    """``view`` under a one-line title bar (cut, never widening its pane)."""
    box = QWidget()
    lay = QVBoxLayout(box)
    lay.setContentsMargins(0, 0, 0, 0)
    lay.setSpacing(0)
    header = QWidget()
    header.setStyleSheet("background:#2b2b2b; color:#ddd;")
    row = QHBoxLayout(header)
    row.setContentsMargins(0, 0, 2, 0)
    row.setSpacing(2)
    label = QLabel(f"  {title}")
    label.setStyleSheet("padding:2px;")
    label.setToolTip(title)
    label.setSizePolicy(QSizePolicy.Policy.Ignored, QSizePolicy.Policy.Fixed)
    row.addWidget(label, 1)
    clear = QToolButton()  # shown for an optional input (InputsPane.rebuild)
    clear.setText("Clear")
    clear.setAutoRaise(True)
    clear.hide()
    row.addWidget(clear)
    lay.addWidget(header)
    lay.addWidget(view)
    box.label = label
    box.clear_button = clear
    return box


class InputsPane(QSplitter):
    """See the module docstring."""

    message = Signal(str)
    dragging = Signal(str, object)
    painting = Signal(str, object, object)  # key, mask so far (None: cancelled), box of the latest dab
    hovered = Signal(object, int, int)  # view, x, y
    zoomed = Signal(object, float)  # view, scale
    open_requested = Signal(str, str)
    clear_requested = Signal(str)  # an optional input's "Clear" button

    def __init__(self, doc, parent=None):
        super().__init__(Qt.Orientation.Vertical, parent)
        self.doc = doc
        self.views: dict[str, ImageView] = {}
        self._boxes: dict[str, QWidget] = {}
        self._tools: dict[tuple, Tool] = {}
        self._toolsets: dict[tuple, ToolSet] = {}
        self._bars: dict[str, GeometryBar] = {}
        self.lines_panel: FeatureLinesPanel | None = None
        self.canvas = QStackedWidget()
        self.tabs = QTabWidget()
        self.addWidget(self.canvas)
        self.addWidget(self.tabs)

    # --- parts ----------------------------------------------------------------------------------
    def view(self, name: str) -> ImageView:
        """The view of input ``name`` (made on first use)."""
        view = self.views.get(name)
        if view is None:
            view = ImageView(self.canvas, title=name)  # (a QSplitter parent would adopt it as a pane)
            view.hovered.connect(lambda x, y, v=view: self.hovered.emit(v, x, y))
            view.zoomed.connect(lambda scale, v=view: self.zoomed.emit(v, scale))
            view.file_dropped.connect(lambda path, n=name: self.open_requested.emit(n, path))
            view.image_shown.connect(lambda n=name: self._image_shown(n))
            self.views[name] = view
            self._boxes[name] = titled(view, name)
            self._boxes[name].clear_button.clicked.connect(lambda _=False, n=name: self.clear_requested.emit(n))
        return view

    def box(self, name: str) -> QWidget:
        """The titled box that shows input ``name`` (its tab's page; an optional input's box has a
        ``clear_button``)."""
        self.view(name)
        return self._boxes[name]

    @property
    def canvas_view(self) -> ImageView:
        return self.view(self.doc.studio.canvas)

    def tool(self, geometry, input_name: str) -> Tool:
        """The tool that edits ``geometry`` on the view of ``input_name`` (made on first use)."""
        key = (geometry.kind, geometry.key, input_name)
        tool = self._tools.get(key)
        if tool is None:
            view = self.view(input_name)
            if geometry.kind == SQUARE:
                tool = PatchTool(
                    view, self.doc, geometry.key, on_drag=lambda square, k=geometry.key: self.dragging.emit(k, square)
                )
            elif geometry.kind == MASK:
                tool = MaskTool(
                    view,
                    self.doc,
                    geometry,
                    on_stroke=lambda mask, box, k=geometry.key: self.painting.emit(k, mask, box),
                )
            elif geometry.kind == MARGINS:
                tool = MarginsTool(view, self.doc, geometry, on_drag=lambda m, k=geometry.key: self.dragging.emit(k, m))
            elif geometry.kind == LINES:
                # one lines panel (with the frontal frame), on the view of the first lines geometry met
                if self.lines_panel is None:
                    self.lines_panel = FeatureLinesPanel(self.doc, view, input_name, self)
                    self.lines_panel.message.connect(self.message)
                tool = self.lines_panel.photo_lines
            else:
                raise ValueError(f"the studio has no tool for {geometry.kind!r} geometry")
            self._tools[key] = tool
        return tool

    # --- following the document -----------------------------------------------------------------
    def rebuild(self) -> None:
        """Lay the current method's inputs out (canvas on top, the others in tabs) with their tools."""
        method, studio = self.doc.current, self.doc.studio
        while self.canvas.count():
            self.canvas.removeWidget(self.canvas.widget(0))
        self.tabs.clear()
        self.view(studio.canvas)
        self.canvas.addWidget(self._boxes[studio.canvas])
        if self.lines_panel is not None:
            self.lines_panel.set_active(False)
        for inp in method.inputs:
            if self.doc.mask_geometry(inp.name) is not None:
                continue  # painted over its image, not a view of its own
            view = self.view(inp.name)
            view.set_image(self.doc.image(inp.name))
            view.set_transparency(self._alpha(inp.name))
            self._show_clear(inp.name, optional=not inp.required)
            if inp.name == studio.canvas:
                continue
            # short tab titles (the input's name; "optional" is in its title bar and tooltip) so the
            # tabs fit a narrow pane instead of being cut or scrolled away
            pretty = inp.name.replace("_", " ")
            i = self.tabs.addTab(self._boxes[inp.name], pretty)
            self.tabs.setTabToolTip(i, f"{pretty}{'' if inp.required else ' (optional)'}: {inp.help}")
        lines = next((g for g in studio.geometry if g.kind == LINES), None)
        if lines is not None:
            self.tool(lines, lines.input_for(self.doc.inputs))
            self.tabs.insertTab(0, self.lines_panel, "frontal frame")
            self.tabs.setTabToolTip(
                0, "the frontal frame: the photo rectified live from the feature lines; draw each line's partner here"
            )
            self.lines_panel.set_active(True)
        self.tabs.setCurrentIndex(0)
        self.tabs.setVisible(self.tabs.count() > 0)
        self.sync_tools()
        if self.paints_on_canvas() and self.tabs.count():  # the painted picture gets most of the height
            total = max(sum(self.sizes()), 400)
            self.setSizes([int(total * 0.78), total - int(total * 0.78)])

    def paints_on_canvas(self) -> bool:
        """The current method's canvas carries a painted mask: painting is the main work, on the
        large view."""
        return any(
            g.kind == MASK and g.input_for(self.doc.inputs) == self.doc.studio.canvas for g in self.doc.studio.geometry
        )

    def sync_tools(self) -> None:
        """Attach each geometry's tool to the view of the input it is drawn on now (others none), and
        title each view with its input and what to draw on it."""
        studio = self.doc.studio
        for inp in self.doc.current.inputs:
            if self.doc.mask_geometry(inp.name) is not None:
                continue
            help_ = " — ".join(g.help for g in studio.geometry if g.input_for(self.doc.inputs) == inp.name)
            self.view(inp.name)
            optional = "" if inp.required else " (optional)"
            self._boxes[inp.name].label.setText(f"  {inp.name.replace('_', ' ')}{optional} — {help_ or inp.help}")
        per_view: dict[str, list[Tool]] = {}
        for g in studio.geometry:
            name = g.input_for(self.doc.inputs)
            per_view.setdefault(name, []).append(self.tool(g, name))
        active = {t for tools in per_view.values() for t in tools}
        for tool in self._tools.values():
            if tool not in active:
                tool.hide()
        wanted: dict[str, Tool] = {}
        for name, tools in per_view.items():
            if len(tools) == 1:
                wanted[name] = tools[0]
            else:
                wanted[name] = self._toolsets.setdefault(tuple(tools), ToolSet(tools))
            self._bar(name).attach(
                [t for t in tools if isinstance(t, MaskTool)] or None,
                next((t for t in tools if isinstance(t, MarginsTool)), None),
            )
        for name, bar in self._bars.items():
            if name not in per_view:
                bar.attach(None, None)
        for name, view in self.views.items():
            tool = wanted.get(name)
            if isinstance(view.tool, QuadTool) and tool is not None and tool.view is view:
                continue  # the lines panel's four-click mode stays until it is done
            view.tool = tool
            if tool is not None:
                tool.refresh()

    def _bar(self, name: str) -> GeometryBar:
        """The mask and margins buttons over the view of input ``name`` (made on first use)."""
        bar = self._bars.get(name)
        if bar is None:
            bar = GeometryBar(self.doc)
            bar.message.connect(self.message)
            self._boxes[name].layout().insertWidget(1, bar)
            self._bars[name] = bar
        return bar

    def mask_tool(self) -> MaskTool | None:
        """The current method's mask tool (its first mask geometry), or None."""
        g = self.doc.geometry_of(MASK)
        return None if g is None else self._tools.get((g.kind, g.key, g.input_for(self.doc.inputs)))

    def margins_tool(self) -> MarginsTool | None:
        g = self.doc.geometry_of(MARGINS)
        return None if g is None else self._tools.get((g.kind, g.key, g.input_for(self.doc.inputs)))

    def bar(self) -> GeometryBar | None:
        """The bar of the current method's mask or margins tool, or None."""
        tool = self.mask_tool() or self.margins_tool()
        return None if tool is None else self._bars.get(next(n for n, v in self.views.items() if v is tool.view))

    def _image_shown(self, name: str) -> None:
        """A large image reached its view after its conversion (``ImageView.image_shown``): the
        geometry drawn on it (a mask, margins) fits it now."""
        view = self.views[name]
        if view.tool is not None:
            view.tool.refresh()
        bar = self._bars.get(name)
        if bar is not None:
            bar.refresh()

    def _alpha(self, name: str):
        """The alpha channel of input ``name`` as the current method sees it, or None."""
        item = self.doc.item(name)
        return None if item is None else item.alpha

    def input_changed(self, name: str) -> None:
        self.view(name).set_image(self.doc.image(name), fit=True)
        self.view(name).set_transparency(self._alpha(name))
        spec = next((i for i in self.doc.current.inputs if i.name == name), None)
        self._show_clear(name, optional=spec is not None and not spec.required)
        self.sync_tools()
        if self.lines_panel is not None and name == self.lines_panel.input_name:
            self.lines_panel.photo_changed()

    def _show_clear(self, name: str, *, optional: bool) -> None:
        """An optional input's title bar has a "Clear" button, enabled while the input is open."""
        button = self._boxes[name].clear_button
        button.setVisible(optional)
        is_open = self.doc.image(name) is not None
        button.setEnabled(is_open)
        pretty = name.replace("_", " ")
        button.setToolTip(
            f"remove the {pretty} (the method runs without it; Ctrl+Z brings it back)"
            if is_open
            else f"no {pretty} is open (optional)"
        )

    def geometry_changed(self) -> None:
        self.sync_tools()
        for bar in self._bars.values():
            bar.refresh()
        if self.lines_panel is not None and self.lines_panel.active:
            self.lines_panel.lines_changed()

    def square_on(self) -> tuple[str, object] | None:
        """(input, geometry) of the current method's square, or None."""
        g = self.doc.geometry_of(SQUARE)
        return None if g is None else (g.input_for(self.doc.inputs), g)

    def shutdown(self) -> None:
        if self.lines_panel is not None:
            self.lines_panel.shutdown()
