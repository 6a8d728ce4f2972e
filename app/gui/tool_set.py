"""Several tools on one view: the masks painted on an image and an uncrop's margins.

A press goes to the tool that claims it (the armed mask tool claims a press whose brush would
paint), else to the first that wants it (the margins tool wants presses outside the image), else to
the armed mask tool; hover moves reach every tool that could take a press (the pointer shows which:
the brush's circle, or a resize arrow over what drags the canvas edges). Mask tools that are not
armed (another mask of the image is being painted) take no press, no hover and no size keys.

**The rule with a mask and margins on one view:** outside the image, a brush or eraser press paints
while the brush's circle covers a pixel of the image (an artist painting along the border gets
paint); a press farther out, any press outside the image in a lasso mode, or a Shift+press outside
the image drags the canvas edges.
"""

from __future__ import annotations

from PySide6.QtCore import Qt

from .margins_tool import MarginsTool
from .tools import Tool


class ToolSet(Tool):
    """Several tools on one view (module docstring): the rest of a drag goes to the tool its press
    went to; keys to the dragging tool first."""

    def __init__(self, tools):
        self.tools = list(tools)
        self.view = self.tools[0].view
        self.grabbed: Tool | None = None
        for tool in self.tools:
            if isinstance(tool, MarginsTool):
                tool.hover_cursor = False  # shown here, when the press would be its

    def _ready(self) -> list[Tool]:
        """The tools that may take a press now (not a mask tool another one is armed instead of)."""
        return [t for t in self.tools if getattr(t, "armed", True)] or self.tools

    def _pick(self, pos, modifiers=Qt.KeyboardModifier.NoModifier) -> Tool:
        ready = self._ready()
        for tool in ready:
            claims = getattr(tool, "claims", None)
            if claims is not None and claims(pos, modifiers):
                return tool
        for tool in ready:
            wants = getattr(tool, "wants", None)
            if wants is not None and wants(pos):
                return tool
        return next((t for t in ready if getattr(t, "wants", None) is None), ready[-1])

    def press(self, view, pos, event):
        self.grabbed = self._pick(pos, event.modifiers())
        self.grabbed.press(view, pos, event)

    def move(self, view, pos, event):
        if self.grabbed is not None and event.buttons() & Qt.MouseButton.LeftButton:
            self.grabbed.move(view, pos, event)
            return
        picked = self._pick(pos, event.modifiers())
        ready = self._ready()
        for tool in self.tools:
            if isinstance(tool, MarginsTool):
                tool.show_arrow(None)
        for tool in [t for t in ready if t is not picked] + [picked]:
            tool.move(view, pos, event)
        if isinstance(picked, MarginsTool):
            picked.show_arrow(pos)

    def release(self, view, pos, event):
        tool, self.grabbed = self.grabbed, None
        if tool is not None:
            tool.release(view, pos, event)

    def leave(self) -> None:
        for tool in self.tools:
            leave = getattr(tool, "leave", None)
            if leave is not None:
                leave()
            if isinstance(tool, MarginsTool) and tool.drag is None:
                tool.show_arrow(None)

    def key(self, view, event) -> bool:
        order = ([self.grabbed] if self.grabbed is not None else []) + [t for t in self.tools if t is not self.grabbed]
        return any(t.key(view, event) for t in order)

    def refresh(self) -> None:
        for tool in self.tools:
            tool.refresh()

    def hide(self) -> None:
        for tool in self.tools:
            tool.hide()
