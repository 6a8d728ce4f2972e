"""The window's layout policy: its docks (Method, Examples) and the split between the inputs and the
result, for the window's width and for what the method does.

* Below ``NARROW`` px the Examples panel is a tab behind the Method panel (the result view is
  ~200 px wide at 1024 px otherwise), and the Method panel takes at most 30 % of the width (its
  parameters scroll); the splitter gives the result the larger share of the rest.
* A method that paints on its canvas gives the inputs pane the larger share (up to 60 %; the
  result beside it keeps ``RESULT_MIN`` px), or 68 % with View > Large Picture to Paint.
"""

from __future__ import annotations

from collections.abc import Callable

from PySide6.QtCore import QMimeData, QSize, Qt, QUrl
from PySide6.QtGui import QIcon
from PySide6.QtWidgets import QDockWidget, QListWidget, QListWidgetItem, QMainWindow, QSplitter
from weft.core.examples import examples

NARROW = 1200  # a window narrower than this (px) gets the Examples panel as a tab behind the Method panel
EXAMPLES_WIDTH = 170  # the Examples panel's width in a wider window: two columns of thumbnails
RESULT_MIN = 360  # the result view's width (px) when the picture painted on takes the larger share


class ExampleList(QListWidget):
    """The bundled examples as thumbnails; drag one onto a view to open it there."""

    def __init__(self, open_example: Callable[[str], None], parent=None):
        super().__init__(parent)
        self.setViewMode(QListWidget.ViewMode.IconMode)
        self.setIconSize(QSize(64, 64))
        self.setResizeMode(QListWidget.ResizeMode.Adjust)
        self.setMovement(QListWidget.Movement.Static)
        self.setDragEnabled(True)
        self.setSpacing(4)
        for path in examples():
            item = QListWidgetItem(QIcon(str(path)), path.stem)
            item.setData(Qt.ItemDataRole.UserRole, str(path))
            item.setToolTip(
                f"{path.name}: double-click to open it as the method's first input, drag onto a view to open it there"
            )
            self.addItem(item)
        self.itemDoubleClicked.connect(lambda item: open_example(item.data(Qt.ItemDataRole.UserRole)))

    def mimeData(self, items):  # noqa: N802 (Qt naming)
        data = QMimeData()
        data.setUrls([QUrl.fromLocalFile(i.data(Qt.ItemDataRole.UserRole)) for i in items])
        return data


class DockLayout:
    """Lays out ``window``'s ``method_dock`` and ``examples_dock`` and its ``splitter`` (inputs pane,
    result) for its width and its method (see the module docstring). ``paints_on_canvas()``: the
    current method paints on its canvas; ``paint_large()``: the user asked for the larger share then."""

    def __init__(
        self,
        window: QMainWindow,
        method_dock: QDockWidget,
        examples_dock: QDockWidget,
        splitter: QSplitter,
        paints_on_canvas: Callable[[], bool],
        paint_large: Callable[[], bool],
    ):
        self.window, self.method_dock, self.examples_dock, self.splitter = window, method_dock, examples_dock, splitter
        self.paints_on_canvas, self.paint_large = paints_on_canvas, paint_large
        self.default_state = None  # the window's first layout (View > Reset Layout)
        self.sized = False  # laid out on the first show
        self._split_share: bool | None = None  # whether the last split was for a method painting on its canvas

    def first_show(self, restored: bool) -> None:
        """The window's first show: a layout restored from last time keeps its docks; else they are
        laid out for the window's size. Either way the result gets its share of the splitter."""
        if self.sized:
            return
        self.sized = True
        if restored:
            self.split(max(self.splitter.width(), 400))
        else:
            self.lay_out_for_width()

    def resized(self, old_width: int) -> None:
        """Made narrow (or wide again): the docks change place and the result view keeps its share."""
        width = self.window.width()
        if self.sized and old_width > 0 and (old_width < NARROW) != (width < NARROW):
            self.lay_out_for_width()

    def reset(self) -> None:
        """Every panel shown and docked where the studio first put it; the result gets the larger share."""
        self.window.restoreState(self.default_state)
        for dock in (self.method_dock, self.examples_dock):
            dock.setFloating(False)
            dock.show()
        self.lay_out_for_width()

    def lay_out_for_width(self) -> None:
        """Dock widths for the window's width, so the result view keeps a usable share."""
        window, method, examples = self.window, self.method_dock, self.examples_dock
        width = window.width()
        method_width = max(method.widget().minimumSizeHint().width(), min(390, int(width * 0.3)))
        if width < NARROW:
            if (
                window.dockWidgetArea(examples) != window.dockWidgetArea(method)
                and not examples.isFloating()
                and not method.isFloating()
            ):
                window.tabifyDockWidget(method, examples)
            method.raise_()
            window.resizeDocks([method], [method_width], Qt.Orientation.Horizontal)
        else:
            if window.dockWidgetArea(examples) != Qt.DockWidgetArea.LeftDockWidgetArea and not examples.isFloating():
                window.addDockWidget(Qt.DockWidgetArea.LeftDockWidgetArea, examples)
            window.resizeDocks([examples, method], [EXAMPLES_WIDTH, method_width], Qt.Orientation.Horizontal)
        self.split(max(width - method_width - (0 if width < NARROW else EXAMPLES_WIDTH) - 24, 400))

    def canvas_share(self, total: int) -> float:
        """The inputs pane's share of the splitter's ``total`` width: when the method paints on its
        canvas, the larger (the result, a preview, beside it keeps RESULT_MIN px), else 45 % (the
        result is what is looked at)."""
        if not self.paints_on_canvas():
            return 0.45
        if self.paint_large():
            return 0.68
        return max(0.45, min(0.6, (total - RESULT_MIN) / max(total, 1)))

    def split(self, total: int) -> None:
        share = self.canvas_share(total)
        self._split_share = self.paints_on_canvas()
        self.splitter.setSizes([int(total * share), total - int(total * share)])

    def resplit(self) -> None:
        """The split follows at once (View > Large Picture to Paint)."""
        self.split(max(sum(self.splitter.sizes()), 400))

    def resplit_for_method(self) -> None:
        """After a method change: the split follows whether the new method paints on its canvas."""
        if self.sized and self._split_share != self.paints_on_canvas():
            self.resplit()
