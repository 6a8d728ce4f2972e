"""Contact sheets of the fill suite: input, weft, best peer and truth side by side, cropped around
the hole and enlarged, saved as a small palette PNG (the committed sheets stay a few MB in all)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

PANEL = 224  # each panel's longer side in px
MARGIN = 20  # px of known picture kept around the hole's bounding box


def _rgb(img: np.ndarray) -> np.ndarray:
    return img if img.ndim == 3 else np.repeat(img[..., None], 3, axis=2)


def _crop_box(hole: np.ndarray) -> tuple[slice, slice]:
    ys, xs = np.nonzero(hole)
    h, w = hole.shape
    y0, y1 = max(0, ys.min() - MARGIN), min(h, ys.max() + 1 + MARGIN)
    x0, x1 = max(0, xs.min() - MARGIN), min(w, xs.max() + 1 + MARGIN)
    return slice(y0, y1), slice(x0, x1)


def contact_sheet(path: Path, inputs, weft: np.ndarray, peer: np.ndarray | None, peer_name: str, note: str) -> None:
    """Write ``path``: four panels (the input with its hole in magenta, weft's fill, the best peer's,
    the truth), each the hole's neighbourhood scaled to :data:`PANEL` px (nearest neighbour when
    enlarged, so pixels stay visible), with labels."""
    from PIL import Image, ImageDraw

    box = _crop_box(inputs.hole)
    shown = _rgb(inputs.image).copy()
    shown[inputs.hole] = (255, 0, 255)
    panels = [
        ("input", shown),
        ("weft", _rgb(weft)),
        (f"best peer: {peer_name}", None if peer is None else _rgb(peer)),
        ("truth", _rgb(inputs.truth)),
    ]
    ch, cw = box[0].stop - box[0].start, box[1].stop - box[1].start
    scale = max(PANEL / max(ch, cw), 120 / cw)  # a panel at least 120 px wide, so its label reads
    size = (max(1, round(cw * scale)), max(1, round(ch * scale)))
    label = 14
    sheet = Image.new("RGB", (4 * size[0] + 3 * 4, size[1] + 2 * label), (40, 40, 40))
    draw = ImageDraw.Draw(sheet)
    for i, (name, img) in enumerate(panels):
        x = i * (size[0] + 4)
        draw.text((x + 2, 1), name[: max(4, size[0] // 6)], fill=(230, 230, 230))
        if img is None:
            continue
        tile = Image.fromarray(np.ascontiguousarray(img[box])).resize(
            size, Image.NEAREST if scale >= 1 else Image.LANCZOS
        )
        sheet.paste(tile, (x, label))
    draw.text((2, size[1] + label + 1), note[:150], fill=(200, 200, 200))
    path.parent.mkdir(parents=True, exist_ok=True)
    sheet.quantize(colors=128, method=Image.Quantize.MEDIANCUT, dither=Image.Dither.NONE).save(path, optimize=True)
