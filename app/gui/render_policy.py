"""What a change of the document renders: the renderer's one place that decides preview or full.

:class:`RenderPolicy` listens to the document's signals for its renderer:

* an edit (an input, the method, the geometry, the seed, a restore, a parameter let go) renders in full;
* a slider held (``Document.drag_param``) previews at reduced size;
* a geometry dragged whose studio description asks for a live result (``Geometry.live``) previews;
* a stroke of the mask its method previews around (``Studio.preview_around``) previews around the
  stroke's latest dab;
* an edit in progress dropped (``live_changed(None)``): a slider let go renders in full; a stroke or
  a drag cancelled drops its previews and the renderer says ``withdrawn`` unless the last result is
  shown again.
"""

from __future__ import annotations

from PySide6.QtCore import QObject


class RenderPolicy(QObject):
    """Turns the document's changes into the renderer's requests (see the module docstring)."""

    def __init__(self, doc, renderer):
        super().__init__(renderer)
        self.doc, self.renderer = doc, renderer
        self._live_seen = None  # the document's edit in progress, as last heard
        for signal in (doc.input_changed, doc.method_changed, doc.restored, doc.geometry_changed, doc.seed_changed):
            signal.connect(self._on_edit)
        doc.params_changed.connect(self._on_params)
        doc.live_changed.connect(self._on_live)

    def _on_edit(self, *_args) -> None:
        self._live_seen = self.doc.live
        self.renderer.final()

    def _on_params(self) -> None:
        live = self.doc.live
        self._live_seen = live
        if live is not None and live.param:
            self.renderer.preview()  # a slider held: its release renders in full
        else:
            self.renderer.final()

    def _on_live(self, edit) -> None:
        ended, self._live_seen = self._live_seen, edit
        doc, renderer = self.doc, self.renderer
        if edit is None:
            if ended is not None and ended.param:
                renderer.final()  # a slider let go (changed or not): the full size
            elif ended is not None and not renderer.stroke_cancelled():
                renderer.withdrawn.emit()
            return
        around = doc.mask_geometry(doc.studio.preview_around) if doc.studio.preview_around else None
        if around is not None and edit.key == around.key and edit.box is not None:
            renderer.preview_around(edit.box)
            return
        g = next((g for g in doc.studio.geometry if g.key == edit.key), None)
        if g is not None and g.live is not None and g.live(doc.current_params):
            renderer.preview()  # the method asks for a live result while this geometry moves
