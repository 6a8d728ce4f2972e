"""What the result view shows: the renderer's results, or the canvas input and what to draw on it.

:class:`ResultState` listens to the renderer and keeps the one piece of state the window had about
results: whether the result view shows the canvas input instead of a result (the method has nothing
to do yet: nothing drawn), and in which words. Then there is no result to export or copy (the
renderer's last result is older than the document), which :meth:`ResultState.nothing_to_export`
says in one line.
"""

from __future__ import annotations

from collections.abc import Callable

from PySide6.QtCore import QObject
from PySide6.QtWidgets import QApplication, QStatusBar
from weft.core.studio import MARGINS, MASK

from .convert import to_qimage
from .render import FailureKind, RenderFailure, describe
from .result_view import ResultView
from .status import ElidedLabel


class ResultState(QObject):
    """The result view and the result's figures, following the renderer (see the module docstring)."""

    def __init__(
        self,
        doc,
        renderer,
        view: ResultView,
        label: ElidedLabel,
        bar: QStatusBar,
        show_message: Callable[[str], None],
        parent=None,
    ):
        super().__init__(parent)
        self.doc, self.renderer, self.view, self.label, self.bar = doc, renderer, view, label, bar
        self.show_message = show_message
        self.input_shown: str | None = None  # what to draw, while the canvas input is shown instead of a result
        renderer.shown.connect(self._on_shown)
        renderer.around_shown.connect(self._on_around_shown)
        renderer.partial.connect(lambda img: self.view.set_image(img))
        renderer.preparing.connect(self.view.set_notice)
        renderer.progress.connect(lambda *_: self.view.set_notice(None))
        renderer.busy.connect(lambda busy: None if busy else self.view.set_notice(None))
        renderer.failed.connect(self._on_failed)
        renderer.needs.connect(self._on_needs)
        renderer.cancelled.connect(self._on_cancelled)
        renderer.withdrawn.connect(self.show_before)

    def _on_around_shown(self, shown) -> None:
        self.view.set_notice(None)
        # (only the part pasted is redrawn: the rest is what the view shows already)
        self.view.set_image(shown.image, changed=shown.changed, over=shown.over)
        self.label.set_full_text(describe(shown))  # (it says it is around the stroke)

    def _on_shown(self, shown) -> None:
        self.input_shown = None
        self.view.set_stale(None)  # a render succeeded: what is shown follows the panel
        self.view.set_notice(None)
        self.view.set_image(shown.image)
        if shown.before is not None and shown.before is not self.view.compare_image:
            self.view.set_compare(shown.before)  # the input of this result, not of the panel
        self.label.set_full_text(describe(shown))

    def _nothing_drawn(self) -> str | None:
        """What to draw, when the current method works on a drawn region (a mask, margins) and none
        is drawn yet: its geometry's help, e.g. "paint what to fill"."""
        # (a mask that means "every pixel" unpainted, a sampling area, is not what there is to do)
        geometry = [g for g in self.doc.studio.geometry if not g.empty_is_all]
        if not any(g.kind in (MASK, MARGINS) for g in geometry) or any(
            self.doc.value(g.key) is not None for g in geometry
        ):
            return None
        words = "; ".join(g.help for g in geometry if g.help) or "draw on the input"
        return words[0].upper() + words[1:]

    def _on_failed(self, failure: RenderFailure) -> None:
        rendering = failure.kind is FailureKind.RENDER
        draw = self._nothing_drawn() if rendering else None
        if draw is not None:
            # nothing drawn yet is not a failure: the input, and what to draw on it (not "render failed"
            # with the command line's options)
            self.show_message(draw)
            self._show_input(draw)
            return
        self.show_message(failure.message)
        if rendering:  # (not a background job's): the result no longer matches the panel
            self.view.set_stale(
                f"Out of date — {failure.message}. The result shown is from earlier settings (F5 renders again)."
            )
        if self.renderer.last is not None:
            self.view.set_image(self.renderer.last.image)

    def _on_needs(self, words: str) -> None:
        """The method renders nothing until something is drawn: the input, and what to draw on it."""
        self._show_input(words[0].upper() + words[1:])

    def _show_input(self, words: str) -> None:
        self.input_shown, self.renderer.input_shown = words, True
        self.show_before()

    def show_before(self) -> None:
        """Show again what the result view showed before a stroke's previews or a cancelled render:
        the canvas input and what to draw on it while nothing is drawn, else the last result."""
        if self.input_shown is not None:
            self.view.set_stale(None)
            self.label.set_full_text("")  # (no result is shown)
            self.view.set_image(self.doc.image(self.doc.studio.canvas))
            self.view.set_notice(self.input_shown)
            self.bar.showMessage(self.input_shown, 8000)
        elif self.renderer.last is not None:
            self.view.set_image(self.renderer.last.image)
            self.label.set_full_text(describe(self.renderer.last))

    def _on_cancelled(self) -> None:
        self.show_before()
        self.bar.showMessage("cancelled; the previous result is kept", 4000)

    def nothing_to_export(self, doing: str = "export") -> str | None:
        """Why there is no result to export or copy now (one line), or None: none rendered in full
        yet, or the input shown instead of one (the method has nothing to do: what to draw)."""
        if self.input_shown is not None:
            return f"nothing to {doing}: {self.input_shown[0].lower()}{self.input_shown[1:]}"
        if self.renderer.last is None or not self.renderer.last.final:
            return f"nothing to {doing} yet: wait for the full-size result"
        return None

    def copy_result(self) -> bool:
        """Put the shown full-size result (not a preview) on the clipboard as an image."""
        why = self.nothing_to_export("copy")
        if why is not None:
            self.show_message(why)
            return False
        shown = self.renderer.last
        QApplication.clipboard().setImage(to_qimage(shown.image))
        h, w = shown.image.shape[:2]
        self.bar.showMessage(f"result {w}x{h} copied to the clipboard", 4000)
        return True
