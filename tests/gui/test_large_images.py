"""Large images reach the views without blocking the GUI thread (the brief: "The GUI thread never
blocks on image work"): an image of more than ``display.ASYNC_PIXELS`` pixels is converted for display
on a worker thread, the previous image stays on screen until it is ready, a stale conversion never
replaces a newer image, and what is drawn is what a QPixmap of the image drew before."""

import threading

import numpy as np
import pytest
import weft.app.gui.display as display
from PySide6.QtCore import QRectF, Qt, QTimer
from PySide6.QtGui import QColor, QPainter, QPixmap
from PySide6.QtWidgets import QGraphicsPixmapItem, QGraphicsScene, QGraphicsView
from weft.app.gui.convert import to_qimage
from weft.app.gui.result_view import ResultView
from weft.app.gui.views import ImageView
from weft.core.image import save_image

BIG = 640  # 640² > display.ASYNC_PIXELS (512²): converted on a worker thread


class _Held:
    """``display.display_qimage`` replaced: each call records whether it ran on the GUI thread and
    waits until :meth:`release` (so a test sees what is on screen meanwhile)."""

    def __init__(self, monkeypatch):
        self.real = getattr(display, "display_qimage", None)
        self.on_gui_thread: list[bool] = []
        self.sizes: list[tuple[int, int]] = []
        self.gate = threading.Event()
        self.started = threading.Event()
        monkeypatch.setattr(display, "display_qimage", self, raising=False)

    def __call__(self, image):
        self.on_gui_thread.append(threading.current_thread() is threading.main_thread())
        self.sizes.append(image.shape[:2])
        if image.shape[0] * image.shape[1] > display.ASYNC_PIXELS:
            self.started.set()
            assert self.gate.wait(20), "never released"
        return self.real(image)

    def release(self) -> None:
        self.gate.set()


def _picture(side, seed=0, channels=3):
    shape = (side, side) if channels == 1 else (side, side, channels)
    return np.random.default_rng(seed).random(shape, dtype=np.float32)


def test_a_large_image_is_converted_off_the_gui_thread_and_the_previous_one_stays_until_then(qtbot, monkeypatch):
    view = ImageView()
    qtbot.addWidget(view)
    view.resize(400, 300)
    view.show()
    small, big = _picture(64, 1), _picture(BIG, 2)
    view.set_image(small)
    assert view.image is small  # small: at once
    held = _Held(monkeypatch)
    ticks = []
    timer = QTimer()
    timer.timeout.connect(lambda: held.started.is_set() and ticks.append(1))
    timer.start(5)
    view.set_image(big, fit=True)
    qtbot.waitUntil(lambda: len(ticks) >= 3, timeout=10000)  # the GUI thread runs while it converts ...
    assert view.image is small and view.converting  # ... and the previous image is still the one shown
    assert view.image_size() == (64, 64)
    with qtbot.waitSignal(view.image_shown, timeout=10000):
        held.release()
    timer.stop()
    assert view.image is big and not view.converting and view.image_size() == (BIG, BIG)
    assert held.on_gui_thread == [False]
    assert view.sceneRect() == QRectF(0, 0, BIG, BIG)


def test_a_stale_conversion_never_replaces_a_newer_image(qtbot, monkeypatch):
    view = ImageView()
    qtbot.addWidget(view)
    view.show()
    held = _Held(monkeypatch)
    first, second, last = _picture(BIG, 1), _picture(BIG + 8, 2), _picture(32, 3)
    shown = []
    view.image_shown.connect(lambda: shown.append(view.image))
    view.set_image(first)
    qtbot.waitUntil(held.started.is_set, timeout=10000)
    view.set_image(second)  # waits for the first's conversion
    view.set_image(last)  # small: shown at once, newer than both (the second's wait ends: never converted)
    assert view.image is last and not view.converting
    with qtbot.waitSignal(view._converter._converted, timeout=10000):  # the first's conversion ends ...
        held.release()
    assert view.image is last and shown == [last]  # ... and is not shown over the newer image
    assert held.sizes == [first.shape[:2], last.shape[:2]] and not view.converting


def test_while_one_converts_only_the_newest_waiting_image_is_converted_next(qtbot, monkeypatch):
    """A stream of large images (a final render's partial images, a stroke's previews on a large
    picture) does not queue a conversion per image: the newest replaces the one waiting."""
    view = ImageView()
    qtbot.addWidget(view)
    view.show()
    held = _Held(monkeypatch)
    images = [_picture(BIG + i, i) for i in range(4)]
    view.set_image(images[0])
    qtbot.waitUntil(held.started.is_set, timeout=10000)
    for image in images[1:]:
        view.set_image(image)
    with qtbot.waitSignal(view.image_shown, timeout=10000):
        held.release()
    assert view.image is images[0]  # newer than what was on screen (nothing): shown
    qtbot.waitUntil(lambda: view.image is images[3], timeout=10000)
    assert held.sizes == [images[0].shape[:2], images[3].shape[:2]]  # the two between: never converted


def _reference_grab(image, view: ImageView):
    """What the view drew before: a QGraphicsPixmapItem of ``QPixmap.fromImage(to_qimage(image))``
    with fast transformation, in a view of the same size, transform and background."""
    scene = QGraphicsScene()
    item = QGraphicsPixmapItem(QPixmap.fromImage(to_qimage(image)))
    item.setTransformationMode(Qt.TransformationMode.FastTransformation)
    scene.addItem(item)
    scene.setSceneRect(item.boundingRect())
    ref = QGraphicsView(scene)
    ref.setRenderHint(QPainter.RenderHint.SmoothPixmapTransform, False)
    ref.setTransformationAnchor(QGraphicsView.ViewportAnchor.NoAnchor)
    ref.setResizeAnchor(QGraphicsView.ViewportAnchor.AnchorViewCenter)
    ref.setBackgroundBrush(QColor(60, 60, 60))
    for v in (ref, view):  # (the viewports the same size whatever the zoom)
        v.setHorizontalScrollBarPolicy(Qt.ScrollBarPolicy.ScrollBarAlwaysOff)
        v.setVerticalScrollBarPolicy(Qt.ScrollBarPolicy.ScrollBarAlwaysOff)
    ref.resize(view.size())
    ref.show()
    ref.setTransform(view.transform())
    ref.horizontalScrollBar().setValue(view.horizontalScrollBar().value())
    ref.verticalScrollBar().setValue(view.verticalScrollBar().value())
    grab = ref.viewport().grab().toImage()
    ref.close()
    return grab


@pytest.mark.parametrize("channels", [3, 1, 4, 2])
@pytest.mark.parametrize("side", [96, BIG])
def test_the_view_draws_the_same_pixels_as_a_pixmap_of_the_image(qtbot, channels, side):
    """Colour, grey, RGBA and grey+alpha, converted at once or on a worker thread, fitted and at 3x:
    the viewport shows exactly what the QPixmap of the image showed."""
    image = _picture(side, 5, channels)
    if channels in (2, 4):
        image[..., -1] = np.where(np.arange(side)[None, :] % 7 == 0, 0.0, image[..., -1])  # some fully clear
    view = ImageView()
    qtbot.addWidget(view)
    view.resize(300, 240)
    view.show()
    with qtbot.waitSignal(view.image_shown, timeout=10000):
        view.set_image(image, fit=True)
    for zoom in (None, 3.0):
        if zoom is not None:
            view.zoom_by(zoom / view.scale_factor())
        ours = view.viewport().grab().toImage()
        ref = _reference_grab(image, view)
        assert ours.size() == ref.size() and ours == ref, (channels, side, zoom)


def test_a_large_input_opened_in_the_window_reaches_both_views_off_the_gui_thread(window, qtbot, tmp_path, monkeypatch):
    """File > Open of a large picture (here as the current method's canvas input): decoded and
    converted off the GUI thread; the input view and the result view (the result's Compare "before")
    show it once converted."""
    path = tmp_path / "large.png"
    picture = _picture(BIG, 9)
    save_image(path, picture)
    canvas = window.doc.studio.canvas
    held = _Held(monkeypatch)
    with qtbot.waitSignal(window.doc.changed, timeout=20000):
        window.open_input(canvas, str(path))
    view = window.inputs_pane.canvas_view
    qtbot.waitUntil(held.started.is_set, timeout=10000)
    assert view.converting and (view.image is None or view.image.shape[:2] != (BIG, BIG))
    held.release()
    qtbot.waitUntil(lambda: not view.converting, timeout=10000)
    assert view.image is window.doc.image(canvas) and view.image.shape[:2] == (BIG, BIG)
    assert held.on_gui_thread and not any(
        held.on_gui_thread[i] for i, s in enumerate(held.sizes) if s[0] * s[1] > display.ASYNC_PIXELS
    )


def test_the_compare_image_of_a_large_result_is_converted_off_the_gui_thread(qtbot, monkeypatch):
    view = ResultView()
    qtbot.addWidget(view)
    view.resize(400, 300)
    view.show()
    held = _Held(monkeypatch)
    after, before = _picture(BIG, 1), _picture(BIG, 2)
    view.set_comparing(True)
    view.set_image(after)
    view.set_compare(before)
    qtbot.waitUntil(held.started.is_set, timeout=10000)
    held.release()
    qtbot.waitUntil(lambda: view.image is after and view.compare_image is before, timeout=10000)
    assert held.on_gui_thread == [False, False]
    assert view._clip.isVisible() and view._clip.rect().width() == pytest.approx(BIG / 2)


@pytest.mark.parametrize("channels", [3, 1, 4, 2])
def test_display_pixels_are_qts_own_conversion_of_the_image(qtbot, channels):
    """``display_qimage`` (numpy, off the GUI thread) gives exactly the pixels Qt's conversion of
    ``to_qimage`` gives -- out-of-range values clipped, every alpha level premultiplied as Qt does."""
    from PySide6.QtGui import QImage
    from weft.app.gui.convert import display_qimage

    rng = np.random.default_rng(channels)
    values = np.linspace(-0.1, 1.1, 256, dtype=np.float32)
    image = np.stack([rng.permutation(values) for _ in range(256)])  # (256, 256): every level, shuffled
    if channels > 1:
        image = np.dstack([rng.permutation(image.ravel()).reshape(256, 256) for _ in range(channels)])
    if channels in (2, 4):
        image[..., -1] = np.arange(256, dtype=np.float32)[None, :] / 255.0  # every alpha level
    qt = to_qimage(image)
    qt = qt.convertToFormat(
        QImage.Format.Format_ARGB32_Premultiplied if qt.hasAlphaChannel() else QImage.Format.Format_RGB32
    )
    ours, _pixels = display_qimage(image)
    assert ours.format() == qt.format() and ours == qt


def test_a_part_changed_in_place_is_redrawn_at_once_and_alone(qtbot, monkeypatch):
    """``set_image(image, changed=box)`` with the array on screen (a stroke's preview pasted into the
    result): only the box is converted, at once, and the view then draws exactly the whole array."""
    view = ImageView()
    qtbot.addWidget(view)
    view.resize(300, 240)
    view.show()
    image = _picture(BIG, 4)
    with qtbot.waitSignal(view.image_shown, timeout=10000):
        view.set_image(image, fit=True)
    held = _Held(monkeypatch)
    image[100:140, 200:260] = _picture(60, 8)[:40]  # pasted in place
    view.set_image(image, changed=(200, 100, 260, 140))
    assert held.sizes == [(40, 60)] and held.on_gui_thread == [True]  # the part alone, here and now
    assert view.image is image and not view.converting
    assert view.viewport().grab().toImage() == _reference_grab(image, view)
    other = image.copy()  # another array: converted whole (on a worker), whatever part is named
    view.set_image(other, changed=(0, 0, 8, 8))
    assert view.converting and held.started.wait(10)
    held.release()
    qtbot.waitUntil(lambda: view.image is other, timeout=10000)
    assert held.sizes[-1] == (BIG, BIG)


def test_parts_changed_while_their_array_converts_are_redrawn_once_it_is_shown(qtbot, monkeypatch):
    """A stroke's previews pasted into an array whose whole conversion is on its way (the first
    preview came before the picture was on screen): each part waits for that one conversion and is
    then redrawn alone, so the view draws the array as it is now, the parts pasted after the worker
    read it included; no second whole conversion is asked for (before, every part asked for one, and
    the previews reached the screen in bursts)."""
    view = ImageView()
    qtbot.addWidget(view)
    view.resize(300, 240)
    view.show()
    held = _Held(monkeypatch)
    real = held.real
    read = threading.Event()

    def convert_then_wait(image):  # the worker reads the array first, then waits
        held.on_gui_thread.append(threading.current_thread() is threading.main_thread())
        held.sizes.append(image.shape[:2])
        out = real(image)
        if image.shape[0] * image.shape[1] > display.ASYNC_PIXELS:
            read.set()
            assert held.gate.wait(20), "never released"
        return out

    monkeypatch.setattr(display, "display_qimage", convert_then_wait)
    image = _picture(BIG, 4)
    view.set_image(image, fit=True)
    assert read.wait(10)  # converted as it was; not shown yet
    image[10:30, 20:60] = _picture(40, 5)[:20]  # two previews pasted in place meanwhile
    view.set_image(image, changed=(20, 10, 60, 30), over=image)
    image[300:340, 400:420] = _picture(40, 6)[:, :20]
    view.set_image(image, changed=(400, 300, 420, 340), over=image)
    assert view.converting and held.sizes == [(BIG, BIG)]  # nothing else converted yet
    held.release()
    qtbot.waitUntil(lambda: not view.converting, timeout=10000)
    assert held.sizes == [(BIG, BIG), (20, 40), (40, 20)] and held.on_gui_thread[1:] == [True, True]
    assert view.image is image
    assert view.viewport().grab().toImage() == _reference_grab(image, view)
