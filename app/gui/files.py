"""The studio's files: export, recipes, sessions, and never losing work (ask, autosave, recover).

A result rendered with a painted mask (a mask geometry is an input of its method) is exported with
that mask as a 1-bit PNG beside it, ``OUT.<input>.png`` (``out.png`` -> ``out.mask.png``), which its
recipe names as that input, so ``weft run OUT.png`` reproduces it; a recipe exported alone gets its
mask beside it alike. Sessions keep masks beside the session file (``weft.core.session.Session``).

Image files are encoded and decoded off the GUI thread: an export, its masks, a saved session and
its masks, and a session's images and masks when it is opened, through :func:`off_gui_thread` (the
window keeps painting, user input waits); the autosave's recovery file and its masks on a worker of
its own (nothing waits; a newer autosave replaces one not yet started, and a recovery file removed
meanwhile is not written again).

Contract: :class:`FileActions` is given the window (a parent for dialogs, with ``show_message(text)``,
``statusBar()``, ``settings``, ``questions`` (:class:`~weft.app.gui.questions.Questions`, the one place
the studio asks), ``may_drop_edits(doing)`` and ``nothing_to_export(doing)``), the document and the
renderer. It exports the *shown result* with that result's own recipe (never the
panel's state), and changes the document only through :meth:`Document.restore`. It imports nothing
of the window.
"""

from __future__ import annotations

import dataclasses
import threading
from collections.abc import Callable
from pathlib import Path
from typing import TypeVar

from PySide6.QtCore import QEventLoop, QMetaObject, QObject, Qt, QTimer, Signal
from PySide6.QtWidgets import QFileDialog
from weft.core import registry
from weft.core.errors import WeftError
from weft.core.image import save_image
from weft.core.jobs import JobResult, JobRunner
from weft.core.readfile import file_key
from weft.core.session import Session, write_files, write_masks
from weft.core.studio import MASK, SQUARE

from . import recovery
from .document import DocumentState, InputImage, read_input

T = TypeVar("T")

SAVE_FILTER = "PNG with recipe (*.png);;JPEG (*.jpg *.jpeg);;TIFF 16-bit (*.tif *.tiff)"
AUTOSAVE_MS = 2000  # unsaved edits reach the recovery file at most this long after they are made


def _source_depth(shown) -> int:
    """The bits per sample of a PNG export of ``shown``: 16 when one of the image files its recipe
    names is 16-bit (a 16-bit source keeps its precision), else 8."""
    from weft.core.image import file_bit_depth

    for path in shown.recipe.inputs.values():
        if file_bit_depth(path) == 16:
            return 16
    return 8


def off_gui_thread(fn: Callable[[], T]) -> T:
    """Run ``fn()`` on a worker thread and return its value (or raise its exception).

    For work the caller must wait for (a session's images are decoded before the document is
    touched, an export is written before it is reported): meanwhile the GUI thread runs a local
    event loop that keeps painting and running timers but holds back user input, so the window
    stays alive and nothing can be started twice.
    """
    loop = QEventLoop()
    box: dict = {}

    def work() -> None:
        try:
            box["value"] = fn()
        except BaseException as e:  # handed to the GUI thread and raised there
            box["error"] = e
        finally:
            QMetaObject.invokeMethod(loop, "quit", Qt.ConnectionType.QueuedConnection)

    thread = threading.Thread(target=work, name="weft-open", daemon=True)
    thread.start()
    loop.exec(QEventLoop.ProcessEventsFlag.ExcludeUserInputEvents)
    thread.join()
    if "error" in box:
        raise box["error"]
    return box["value"]


class FileActions(QObject):
    """Export, recipes, sessions, autosave and recovery (see the module docstring)."""

    _autosaved = Signal(object)  # a background autosave's JobResult (queued to the GUI thread)

    def __init__(self, window, doc, renderer):
        super().__init__(window)
        self.window, self.doc, self.renderer = window, doc, renderer
        self.settings = window.settings
        # Crash recovery: while the document has unsaved edits, it is autosaved (atomically) at most
        # every AUTOSAVE_MS; a clean document has no recovery file.
        # (one file per window, with a lock naming its owner: see recovery.py)
        self._me = recovery.Owner.me(recovery.settings_id(self.settings))
        self.recovery_file = recovery.new_recovery_file(recovery.recovery_folder())
        self.session_path: str | None = None  # the session file Ctrl+S saves to (saved, opened or restored)
        self._autosave_timer = QTimer(window, singleShot=True, interval=AUTOSAVE_MS)
        self._autosave_timer.timeout.connect(lambda: self.autosave(wait=False))
        self._owns_recovery = False  # only a file this window wrote (or restored) is removed by it
        # the recovery file's writes: one worker; the lock and generation keep a write from putting
        # back a recovery file that was removed (discard_recovery) while it was being encoded
        self._recovery_lock = threading.Lock()
        self._recovery_generation = 0
        self._autosaver = JobRunner(max_workers=1, on_result=self._autosaved.emit)
        self._autosaved.connect(self._on_autosaved)

    def shutdown(self) -> None:
        """Finish a background autosave that has started (a pending one is dropped) and stop its worker."""
        self._autosave_timer.stop()
        self._autosaver.shutdown(wait=True, cancel=True)

    def show_message(self, text: str) -> None:
        self.window.show_message(text)

    def statusBar(self):  # noqa: N802 (the window's)
        return self.window.statusBar()

    def _confirm(self, question: str) -> bool:
        return self.window.questions.confirm(question)

    # --- export, sessions ------------------------------------------------------------------------
    def _start(self, suffix: str) -> str:
        """Where a save dialog starts: the last folder used (else the home folder, never the
        install's bundled examples), with a name made from the canvas input and the method, e.g.
        ``wood-grain-fast.png``."""
        canvas = self.doc.inputs.get(self.doc.studio.canvas)
        folder = str(self.settings.value("last_dir", "") or "")
        stem = Path(canvas.path).stem if canvas is not None and canvas.path else "weft"
        return str(Path(folder or Path.home()) / f"{stem}-{self.doc.method}{suffix}")

    def _ask_save(self, caption: str, suffix: str, filters: str) -> str:
        path, _ = QFileDialog.getSaveFileName(self.window, caption, self._start(suffix), filters)
        if path:
            self.settings.setValue("last_dir", str(Path(path).parent))
        return path

    def save_result_dialog(self) -> None:
        why = self.window.nothing_to_export()
        if why is not None:
            self.show_message(why)
            return
        path = self._ask_save("Export result", ".png", SAVE_FILTER)
        if path:
            self.export_result(path)

    def export_result(self, path: str) -> bool:
        """Save the shown full-size result: PNG carries the result's recipe (with the bit depth written)
        and is 16-bit when a source image is, TIFF is 16-bit, JPEG 8-bit."""
        why = self.window.nothing_to_export()
        if why is not None:
            self.show_message(why)
            return False
        shown = self.renderer.last
        p = Path(path)
        if p.suffix.lower() not in (".png", ".jpg", ".jpeg", ".tif", ".tiff"):
            p = p.with_suffix(".png")
        key = file_key(p)  # by device and inode: another path to an input (a link, a second mount) is it
        if any(item.path and file_key(item.path) == key for item in self.doc.inputs.values()):
            self.show_message(f"{p.name}: refusing to overwrite an input image")
            return False
        if p.exists() and not self._confirm(f"{p.name} exists. Replace it?"):
            self.show_message(f"{p.name}: not exported (the existing file is kept)")
            return False
        suffix = p.suffix.lower()
        depth = 16 if suffix in (".tif", ".tiff") else 8 if suffix in (".jpg", ".jpeg") else _source_depth(shown)
        try:
            recipe, masks = self._with_masks(shown, p)
            # the bit depth written is recorded: weft run writes the same samples again
            recipe = dataclasses.replace(recipe, bit_depth=depth).to_json(relative_to=p.resolve().parent)
        except WeftError as e:
            self.show_message(str(e))
            return False
        self.statusBar().showMessage(f"exporting {p.name}…")

        def write() -> None:
            write_masks(masks)
            save_image(p, shown.image, recipe=recipe, bit_depth=depth)

        try:  # encoding a large PNG (and its mask's) takes a second: off the GUI thread
            off_gui_thread(write)
        except WeftError as e:
            self.show_message(str(e))
            return False
        self.statusBar().showMessage(f"exported {p}", 5000)
        return True

    def export_recipe_dialog(self) -> None:
        path = self._ask_save("Export recipe", ".json", "Recipe (*.json)")
        if path:
            self.export_recipe(path)

    def export_recipe(self, path: str) -> bool:
        """Save the recipe of the shown full-size result (``weft run`` reproduces its pixels)."""
        why = self.window.nothing_to_export("export")
        if why is not None:
            self.show_message(why.replace("nothing to export", "no recipe to export", 1))
            return False
        shown = self.renderer.last
        try:
            recipe, masks = self._with_masks(shown, Path(path))
            recipe = dataclasses.replace(recipe, bit_depth=_source_depth(shown))  # (as a PNG export's)

            def write() -> None:
                write_masks(masks)
                recipe.save(path)

            off_gui_thread(write)
        except WeftError as e:
            self.show_message(str(e))
            return False
        return True

    def _with_masks(self, shown, beside: Path):
        """``(recipe, masks)``: the recipe of ``shown`` with each painted mask it was rendered with
        named as that input, a 1-bit PNG beside ``beside`` (``out.png`` -> ``out.mask.png``), and
        what ``write_masks`` writes there (file -> mask); nothing is written here."""
        recipe = shown.recipe
        if not shown.masks:
            return recipe, {}
        inputs = dict(recipe.inputs)
        masks = {}
        for name, mask in shown.masks.items():
            file = beside.with_name(f"{beside.stem}.{name}.png")
            if any(item.path and file_key(item.path) == file_key(file) for item in self.doc.inputs.values()):
                raise WeftError(f"{file.name}: refusing to overwrite an input image with the {name.replace('_', ' ')}")
            masks[file] = mask
            inputs[name] = str(file.resolve())
        return dataclasses.replace(recipe, inputs=inputs), masks

    def save_session_quick(self) -> bool:
        """Save to the session file last saved, opened or restored (Ctrl+S); ask where if none."""
        if self.session_path:
            return self.save_session(self.session_path)
        return self.save_session_dialog()

    def save_session_dialog(self) -> bool:
        """Ask where, then save; True if the session was saved."""
        if self.session_path:
            path, _ = QFileDialog.getSaveFileName(
                self.window, "Save session as", self.session_path, "weft session (*.weft.json *.json)"
            )
            if path:
                self.settings.setValue("last_dir", str(Path(path).parent))
        else:
            path = self._ask_save("Save session", ".weft.json", "weft session (*.weft.json *.json)")
        return bool(path) and self.save_session(path)

    def save_session(self, path: str) -> bool:
        session = self.doc.session()  # (captured here; its masks' PNGs are encoded off the GUI thread)
        try:
            off_gui_thread(lambda: session.save(path))
        except WeftError as e:
            self.show_message(str(e))
            return False
        self.session_path = str(path)
        self.doc.undo_stack.setClean()
        self.statusBar().showMessage(f"session saved to {path}", 4000)
        return True

    def open_session_dialog(self) -> None:
        path, _ = QFileDialog.getOpenFileName(
            self.window, "Open session", str(self.settings.value("last_dir", "") or ""), "weft session (*.json)"
        )
        if path:
            self.open_session(path)

    def open_session(self, path: str) -> bool:
        """Replace the document with a saved session (inputs re-read from their files).

        Unsaved edits are saved or discarded as the user chooses first (``window.may_drop_edits``).
        """
        if not self.window.may_drop_edits("open another session"):
            return False
        try:
            data, images = self._read_session_files(path)
        except WeftError as e:
            self.show_message(" ".join(str(e).split()))
            return False
        self._apply_session(data, images)
        self.session_path = str(path)
        self.statusBar().showMessage(f"session {Path(path).name} opened", 4000)
        return True

    def _read_session_files(self, path: str | Path) -> tuple[Session, dict[str, InputImage]]:
        """Read a session and its images, checking everything before the document is touched.

        Raises ``WeftError`` naming the session file and, for an image, which input it is.
        """
        dropped: list[str] = []
        offered = registry.studio_methods()

        def decode() -> tuple[Session, dict[str, InputImage]]:
            data = Session.read(path, dropped=dropped)  # (its mask PNGs decoded); missing or unreadable: the rest opens
            if data.method not in offered:
                raise WeftError(
                    f"{path}: the studio does not offer method {data.method!r} "
                    f"(it offers {', '.join(offered)}; use 'weft {data.method}')"
                )
            images = {}
            for name, p in data.inputs.items():
                try:
                    images[name] = read_input(p)
                except WeftError as e:
                    raise WeftError(f"{path}: the {name.replace('_', ' ')} image: {e}") from None
            return data, images

        self.statusBar().showMessage(f"opening {Path(path).name}…")
        data, images = off_gui_thread(decode)
        for method, values in data.geometry.items():  # a square must lie inside its image
            for g in offered[method].studio.geometry:
                value, on = values.get(g.key), g.input_for(images)
                if g.kind == SQUARE and value is not None and on in images:
                    try:
                        value.crop(images[on].image, what=on.replace("_", " "), name=g.key)
                    except WeftError as e:
                        raise WeftError(f"{path}: {method} {g.key}: {e}") from None
                if g.kind == MASK and value is not None and on in images:  # a mask must fit its image
                    try:
                        value.check_size(images[on].image.shape, what=on.replace("_", " "), name=g.key)
                    except WeftError as e:
                        del values[g.key]
                        dropped.append(f"{path}: {method}: {e}; dropped")
        for line in dropped:  # (said once all is read: a session that does not open drops nothing)
            self.show_message(line)
        return data, images

    def _apply_session(self, data: Session, images: dict[str, InputImage]) -> None:
        """Put a read session into the document (one clean state, no undo history) and render it.
        Each input keeps the method it was opened for (``Studio.own_inputs``: fill's texture is fill's
        only when opened for fill; the brick open for quilt filled a gravel hole after a recovery, seen
        under Xvfb); in a session that did not record it, no own input is taken (an own input a method
        does not get shows as an empty input, which can be opened again; one it gets silently changes the result)."""
        opened_for = data.opened_for or {}  # (not recorded: no own input counts as opened for its method)
        images = {name: dataclasses.replace(item, opened_for=opened_for.get(name)) for name, item in images.items()}
        self.doc.restore(
            DocumentState(inputs=images, method=data.method, params=data.params, geometry=data.geometry, seed=data.seed)
        )
        self.renderer.final(now=True)

    # --- asking, autosave, recovery --------------------------------------------------------------
    def schedule_autosave(self, *_args) -> None:
        """The document changed (or was saved): autosave it soon if it has unsaved edits, else
        remove this window's recovery file."""
        if self.doc.undo_stack.isClean():
            self._autosave_timer.stop()
            if self._owns_recovery:
                self.discard_recovery()
        elif not self._autosave_timer.isActive():
            self._autosave_timer.start()

    def autosave(self, *, wait: bool = True) -> bool:
        """Write the session (absolute paths) to :attr:`recovery_file`, atomically, its masks' PNGs
        beside it, encoded off the GUI thread. The document is captured now.

        ``wait`` (the default): return once written (the window keeps painting meanwhile). Without
        it (the autosave timer) the write runs on the autosave worker and nothing waits: a failure
        is said in the status bar when it happens.

        Returns
        -------
        bool
            True if written (without ``wait``: submitted); False if the document is clean (nothing to
            recover) or the write failed (said once in the status bar; the next edit tries again).
        """
        if self.doc.undo_stack.isClean():
            return False
        session = self.doc.session(saved_as=self.session_path)  # (Ctrl+S after a recovery saves there)
        with self._recovery_lock:
            generation = self._recovery_generation
        self._owns_recovery = True  # (what it writes is this window's to remove, from now)
        if not wait:
            self._autosaver.submit("autosave", lambda **_: self._write_recovery(generation, session))
            return True
        try:
            off_gui_thread(lambda: self._write_recovery(generation, session))
        except (OSError, WeftError) as e:
            self._autosave_failed(e)
            return False
        return True

    def _write_recovery(self, generation: int, session: Session) -> bool:
        """(Any thread.) Encode the session (absolute paths) and its masks, then -- unless the
        recovery was discarded since the autosave was made (``generation``) -- write them. False:
        discarded, nothing written."""
        files = session.files(self.recovery_file, relative=False)  # the slow part, outside the lock
        with self._recovery_lock:
            if generation != self._recovery_generation:
                return False
            self.recovery_file.parent.mkdir(parents=True, exist_ok=True)
            recovery.write_lock(self.recovery_file, self._me)  # (first: a file without its lock is nobody's)
            write_files(files)
        return True

    def _on_autosaved(self, result: JobResult) -> None:
        if result.error is not None:  # (a full disk, a folder gone, out of memory: said, never silent)
            self._autosave_failed(result.error)

    def _autosave_failed(self, e: BaseException) -> None:
        self.show_message(f"{self.recovery_file}: autosave failed ({' '.join(str(e).split())})")

    def discard_recovery(self) -> None:
        """Remove the recovery file (the document is saved, clean, or its edits were discarded); an
        autosave being written meanwhile does not put it back."""
        stem = self.recovery_file.name[:-5] if self.recovery_file.name.endswith(".json") else self.recovery_file.name
        with self._recovery_lock:  # (waits for a write in progress: its files go too)
            self._recovery_generation += 1
            try:
                self.recovery_file.unlink(missing_ok=True)
                for mask in self.recovery_file.parent.glob(f"{stem}.*.png"):  # its masks (Session.mask_files)
                    mask.unlink(missing_ok=True)
                recovery.lock_path(self.recovery_file).unlink(missing_ok=True)
            except OSError:
                pass
        self._owns_recovery = False

    def close(self) -> None:
        """The window closes with nothing unsaved (saved or discarded): no autosave any more, and this
        window's recovery file goes."""
        self._autosave_timer.stop()
        if self._owns_recovery:
            self.discard_recovery()

    def offer_recovery(self) -> bool:
        """Offer to restore the unsaved session of a window that did not close normally.

        Only orphans are offered (recovery.py: written with these settings, their window no longer
        running), the newest first, one question each (Restore is the default button). Restored:
        this window takes the file over (inputs, method, parameters, geometry, seed and the session
        file Ctrl+S saves to; the document counts as unsaved). Declined: that file is removed and the
        next orphan, if any, is offered. Unreadable: said in one line, and kept.
        """
        for path in recovery.orphans(self.recovery_file.parent, self._me.settings):
            if not recovery.claim(path, self._me):
                continue
            when = recovery.modified(path)
            if not self.window.questions.ask_restore(
                f"A weft window did not close normally{f' ({when})' if when else ''}. Restore its unsaved session?"
            ):
                self._discard_file(path)
                continue
            try:
                data, images = self._read_session_files(path)
            except WeftError as e:
                self.show_message(f"could not restore the session: {' '.join(str(e).split())}")
                return False
            self._apply_session(data, images)
            self.recovery_file = path  # this window's from now (its lock names this window)
            self._owns_recovery = True
            self.session_path = data.saved_as
            self.doc.undo_stack.resetClean()  # the restored edits are still unsaved
            self.statusBar().showMessage("unsaved session restored", 4000)
            return True
        return False

    def _discard_file(self, path: Path) -> None:
        """Remove another window's recovery file (declined), its masks and its lock."""
        stem = path.name[:-5]
        try:
            path.unlink(missing_ok=True)
            for mask in path.parent.glob(f"{stem}.*.png"):
                mask.unlink(missing_ok=True)
            recovery.lock_path(path).unlink(missing_ok=True)
        except OSError:
            pass
