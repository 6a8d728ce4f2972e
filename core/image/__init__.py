"""Images in weft: float32 arrays in [0, 1], shape (H, W) grey or (H, W, 3) RGB.

``weft.core.image.files`` loads (its decoders in ``decoding``), ``writing`` saves, ``png_chunks``
reads a PNG's recipe, ``arrays`` validates and resizes (OpenCV's BGR never leaves this package);
``weft.core.image.colour`` holds the colour helpers: luminance (Rec. 601), RGB <-> YIQ, and the
principal-component grey of Smith & Bhalerao §3.4. Everything public is importable from here.
"""

from .colour import PcaBasis, from_pca, luminance, pca_basis, pca_grey, rgb_to_yiq, to_pca, yiq_to_rgb
from .files import (
    DEFAULT_MAX_PIXELS,
    ImageInfo,
    Loaded,
    atomic_write_bytes,
    encode_image,
    file_bit_depth,
    get_max_pixels,
    load_image,
    read_recipe,
    resize,
    save_image,
    set_max_pixels,
    validate_image,
)

__all__ = [
    "DEFAULT_MAX_PIXELS",
    "ImageInfo",
    "Loaded",
    "PcaBasis",
    "atomic_write_bytes",
    "encode_image",
    "file_bit_depth",
    "from_pca",
    "get_max_pixels",
    "load_image",
    "luminance",
    "pca_basis",
    "pca_grey",
    "read_recipe",
    "resize",
    "rgb_to_yiq",
    "save_image",
    "set_max_pixels",
    "to_pca",
    "validate_image",
    "yiq_to_rgb",
]
