"""What a batch's memory allows, checked before any work: the largest item's estimate
(``Method.memory`` on the inputs' header sizes), the items too large to run even alone, and how
many workers fit.
"""

from __future__ import annotations

import os
from collections.abc import Iterable

from ..errors import WeftError
from ..limits import LimitError, _bytes, available_memory
from ..readfile import open_regular, shown
from .items import Item


def _header_shape(path: str) -> tuple[int, ...] | None:
    """(H, W) or (H, W, 3) of an image file from its header, or None if it cannot be read."""
    from ..image.files import _GREY_MODES, _pil_open

    try:
        with open_regular(path, "image file") as f:
            im, _ = _pil_open(open(os.dup(f.fileno()), "rb"))
        with im:
            w, h = im.size
            return (h, w) if im.mode in _GREY_MODES else (h, w, 3)
    except Exception:  # noqa: BLE001 - a bad file fails its own item, with its own message
        return None


def item_memory(items: Iterable[Item]) -> tuple[float, str]:
    """The largest estimated peak memory of one item (``Method.memory`` on the inputs' header sizes).

    Parameters
    ----------
    items : iterable of Item
        The batch's items (one method).

    Returns
    -------
    bytes : float
        The largest estimate; 0 when the method gives none.
    label : str
        That item's label ("" with no estimate).
    """
    from .. import registry

    best, label = 0.0, ""
    items = list(items)
    if not items:
        return best, label
    method = registry.get(items[0].method)
    if method.memory is None:
        return best, label
    params = method.params.from_dict(items[0].params)
    for item in items:
        found = {name: _header_shape(path) for name, path in item.inputs.items()}
        shapes = {name: s for name, s in found.items() if s is not None}
        if len(shapes) < len(found):
            continue
        if item.region is not None:
            first = method.inputs[0].name
            side = item.region[2]
            shapes[first] = (side, side) + tuple(shapes[first][2:])
        try:
            need = float(method.memory(shapes, params))
        except (WeftError, KeyError, TypeError, ValueError):
            continue  # the item's own run refuses it with the precise reason
        if need > best:
            best, label = need, item.label
    return best, label


def too_large_alone(items: Iterable[Item], *, available: int | None = None) -> list[tuple[Item, str]]:
    """The items that cannot run even alone, each with its one-line reason.

    An input whose header claims more pixels than the pixel limit, or an estimated peak memory above
    ``available``. They fail by themselves; the rest of the batch runs.

    Parameters
    ----------
    items : iterable of Item
        The batch's items.
    available : int, optional
        Bytes of memory; default what the system has available now.

    Returns
    -------
    list of (Item, str)
    """
    from .. import registry
    from ..image import get_max_pixels

    items = list(items)
    if not items:
        return []
    method = registry.get(items[0].method)
    params = method.params.from_dict(items[0].params) if method.memory is not None else None
    available = available_memory() if available is None else available
    limit = get_max_pixels()
    alone = []
    for item in items:
        shapes = {name: _header_shape(path) for name, path in item.inputs.items()}
        big = next(((name, s) for name, s in shapes.items() if s is not None and s[0] * s[1] > limit), None)
        if big is not None:
            name, (h, w) = big[0], big[1][:2]
            alone.append(
                (
                    item,
                    f"{shown(item.inputs[name])}: {w}x{h} = {w * h / 1e6:.1f} megapixels exceeds the "
                    f"limit of {limit / 1e6:g} megapixels (set WEFT_MAX_PIXELS to raise it)",
                )
            )
            continue
        known = {name: s for name, s in shapes.items() if s is not None}
        if method.memory is None or params is None or available is None or len(known) < len(shapes):
            continue
        if item.region is not None:
            first = method.inputs[0].name
            known[first] = (item.region[2], item.region[2]) + tuple(known[first][2:])
        try:
            need = float(method.memory(known, params))
        except (WeftError, KeyError, TypeError, ValueError):
            continue
        if need > available:
            alone.append(
                (
                    item,
                    f"needs about {_bytes(need)} of memory, {_bytes(available)} is available: make its inputs smaller",
                )
            )
    return alone


def workers_that_fit(items: Iterable[Item], workers: int, *, available: int | None = None) -> int:
    """How many workers fit in memory at once by the largest item's estimate.

    Parameters
    ----------
    items : iterable of Item
        The batch's items.
    workers : int
        The most workers wanted.
    available : int, optional
        Bytes of memory; default what the system has available now.

    Returns
    -------
    int
        At most ``workers``, at least 1.
    """
    need, _ = item_memory(items)
    available = available_memory() if available is None else available
    if not need or available is None:
        return workers
    return max(1, min(workers, int(available // need)))


def check_memory(
    items: Iterable[Item], workers: int, *, available: int | None = None, option: str = "--workers"
) -> None:
    """Refuse up front a batch whose largest item's estimate times ``workers`` exceeds the memory.

    Parameters
    ----------
    items : iterable of Item
        The batch's items.
    workers : int
        The workers that would run at once.
    available : int, optional
        Bytes of memory; default what the system has available now.
    option : str, default "--workers"
        The option to name in the advice.

    Raises
    ------
    LimitError
        Saying how many workers would fit.
    """
    need, label = item_memory(items)
    available = available_memory() if available is None else available
    if not need or available is None or need * workers <= available:
        return
    fits = int(available // need)
    advice = f"use {option} {fits}" if fits >= 1 else "make the inputs smaller (even one item does not fit)"
    raise LimitError(
        f"batch: one item ({label}) needs about {_bytes(need)} of memory, {workers} workers at once "
        f"{_bytes(need * workers)}, {_bytes(available)} is available: {advice}"
    )
