"""Tests for weft.core.image: loading, saving, recipes in PNGs, validation, resizing, colour helpers."""

from __future__ import annotations

import dataclasses
import os
import struct
import zlib
from pathlib import Path

import cv2
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp
from PIL import Image, ImageOps
from weft.core import image as ci
from weft.core.errors import ImageError, InvalidParameter, WeftError
from weft.core.image import (
    DEFAULT_MAX_PIXELS,
    ImageInfo,
    Loaded,
    atomic_write_bytes,
    from_pca,
    get_max_pixels,
    load_image,
    luminance,
    pca_grey,
    read_recipe,
    resize,
    rgb_to_yiq,
    save_image,
    set_max_pixels,
    to_pca,
    validate_image,
    yiq_to_rgb,
)


@pytest.fixture(autouse=True)
def _clean_limit(monkeypatch):
    monkeypatch.delenv("WEFT_MAX_PIXELS", raising=False)
    set_max_pixels(None)
    yield
    set_max_pixels(None)


def rng_image(shape, seed=0):
    return np.random.default_rng(seed).random(shape).astype(np.float32)


def smooth_rgb(h=32, w=48):
    y, x = np.mgrid[0:h, 0:w].astype(np.float32)
    return np.stack([x / (w - 1), y / (h - 1), 0.5 + 0.4 * np.sin(x / 5)], axis=2).astype(np.float32)


def pil_save(path, pil_image, fmt=None, **kw):
    pil_image.save(path, fmt, **kw)
    return path


def rgb8(seed=0, shape=(6, 9, 3)):
    return np.random.default_rng(seed).integers(0, 256, shape, dtype=np.uint8)


def assert_one_line_error(excinfo, path):
    msg = str(excinfo.value)
    assert "\n" not in msg
    assert msg.startswith(str(path))
    assert Path(path).name in msg
    assert excinfo.value.path == str(path)


# ----------------------------------------------------------------------------------------------
# Round trips


@pytest.mark.parametrize("ext", [".png", ".tif", ".tiff"])
@pytest.mark.parametrize("channels", [1, 3])
def test_round_trip_8bit_is_exact_to_a_quantisation_step(tmp_path, ext, channels):
    shape = (13, 17) if channels == 1 else (13, 17, 3)
    x = rng_image(shape)
    path = tmp_path / f"img{ext}"
    save_image(path, x)
    loaded = load_image(path)
    assert isinstance(loaded, Loaded)
    img, info = loaded
    assert img.dtype == np.float32 and img.flags.c_contiguous
    assert img.shape == shape
    np.testing.assert_array_equal(img, np.rint(x * 255) / np.float32(255))
    assert info.bit_depth == 8 and info.channels == channels
    assert (info.width, info.height) == (17, 13)
    assert info.format == ("PNG" if ext == ".png" else "TIFF")
    assert info.notes == () and info.orientation == 1 and not info.had_alpha


@pytest.mark.parametrize("ext", [".png", ".tif"])
@pytest.mark.parametrize("channels", [1, 3])
def test_round_trip_16bit_keeps_precision(tmp_path, ext, channels):
    shape = (11, 7) if channels == 1 else (11, 7, 3)
    x = rng_image(shape, seed=3)
    path = tmp_path / f"deep{ext}"
    save_image(path, x, bit_depth=16)
    img, info = load_image(path)
    assert info.bit_depth == 16 and img.shape == shape
    err = np.abs(img - x).max()
    assert err <= 0.5 / 65535 + 1e-7
    assert err < 0.1 / 255  # far better than 8 bits


def test_rgb_order_is_kept(tmp_path):
    x = np.zeros((2, 3, 3), np.float32)
    x[..., 0] = 1.0  # pure red
    save_image(tmp_path / "red.png", x)
    img, _ = load_image(tmp_path / "red.png")
    np.testing.assert_array_equal(img[0, 0], [1, 0, 0])
    # and on disk it is red for other readers too
    np.testing.assert_array_equal(np.asarray(Image.open(tmp_path / "red.png"))[0, 0], [255, 0, 0])


@pytest.mark.parametrize("ext", [".jpg", ".jpeg", ".JPG"])
def test_jpeg_round_trip_is_approximate(tmp_path, ext):
    x = smooth_rgb()
    path = tmp_path / f"photo{ext}"
    save_image(path, x, quality=95)
    img, info = load_image(path)
    assert info.format == "JPEG" and img.shape == x.shape
    assert np.abs(img - x).mean() < 0.02
    save_image(tmp_path / f"low{ext}", x, quality=5)
    assert os.path.getsize(tmp_path / f"low{ext}") < os.path.getsize(path)


def test_grey_stays_two_dimensional(tmp_path):
    g = rgb8(shape=(5, 8))
    pil_save(tmp_path / "g.png", Image.fromarray(g))
    pil_save(tmp_path / "g.jpg", Image.fromarray(g))
    img, info = load_image(tmp_path / "g.png")
    assert img.shape == (5, 8) and info.channels == 1
    np.testing.assert_array_equal(img, g / np.float32(255))
    assert load_image(tmp_path / "g.jpg").image.ndim == 2


def test_16bit_grey_written_by_pillow(tmp_path):
    g = np.array([[0, 1, 40000, 65535]], dtype=np.uint16)
    pil_save(tmp_path / "g16.png", Image.fromarray(g))
    img, info = load_image(tmp_path / "g16.png")
    assert info.bit_depth == 16 and img.shape == (1, 4)
    np.testing.assert_allclose(img, g / 65535.0, atol=1e-7)


def test_rgba_drops_alpha_with_a_note(tmp_path):
    rgba = rgb8(shape=(4, 5, 4))
    rgba[..., 3] = 0  # fully transparent: colours are kept as stored, not composited
    pil_save(tmp_path / "a.png", Image.fromarray(rgba, "RGBA"))
    img, info = load_image(tmp_path / "a.png")
    assert img.shape == (4, 5, 3)
    np.testing.assert_array_equal(img, rgba[..., :3] / np.float32(255))
    assert info.had_alpha and "alpha channel dropped" in info.notes and info.channels == 3


def test_grey_alpha_stays_grey(tmp_path):
    la = rgb8(shape=(4, 5, 2))
    pil_save(tmp_path / "la.png", Image.fromarray(la, "LA"))
    img, info = load_image(tmp_path / "la.png")
    assert img.shape == (4, 5) and info.channels == 1
    np.testing.assert_array_equal(img, la[..., 0] / np.float32(255))
    assert info.had_alpha and "alpha channel dropped" in info.notes


def _png_by_hand(path, pixels, colour_type):
    """A minimal 16-bit PNG written chunk by chunk (Pillow cannot write 16-bit grey+alpha)."""

    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))

    h, w = pixels.shape[:2]
    rows = b"".join(b"\0" + pixels[i].astype(">u2").tobytes() for i in range(h))
    ihdr = struct.pack(">IIBBBBB", w, h, 16, colour_type, 0, 0, 0)
    path.write_bytes(
        b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b"")
    )
    return path


def test_16bit_grey_alpha_stays_grey(tmp_path, monkeypatch):
    la = np.random.default_rng(1).integers(0, 65536, (3, 4, 2)).astype(np.uint16)
    path = _png_by_hand(tmp_path / "la16.png", la, colour_type=4)
    img, info = load_image(path)
    assert img.shape == (3, 4) and info.bit_depth == 16 and info.had_alpha and info.channels == 1
    np.testing.assert_allclose(img, la[..., 0] / 65535.0, atol=1e-7)
    rgba = np.random.default_rng(2).integers(0, 65536, (3, 4, 4)).astype(np.uint16)
    img, info = load_image(_png_by_hand(tmp_path / "rgba16.png", rgba, colour_type=6))
    assert img.shape == (3, 4, 3) and info.bit_depth == 16 and "alpha channel dropped" in info.notes
    np.testing.assert_allclose(img, rgba[..., :3] / 65535.0, atol=1e-7)


def test_palette_is_expanded_to_rgb(tmp_path):
    pal = Image.new("P", (3, 2))
    pal.putpalette([255, 0, 0, 0, 255, 0, 0, 0, 255] + [0] * (256 * 3 - 9))
    pal.putdata([0, 1, 2, 2, 1, 0])
    pil_save(tmp_path / "p.png", pal)
    img, info = load_image(tmp_path / "p.png")
    assert img.shape == (2, 3, 3)
    np.testing.assert_array_equal(img[0], np.eye(3, dtype=np.float32))
    np.testing.assert_array_equal(img[1], np.eye(3, dtype=np.float32)[::-1])
    assert "palette expanded to RGB" in info.notes and not info.had_alpha


def test_grey_palette_also_becomes_rgb(tmp_path):
    g = rgb8(shape=(4, 4))
    pil_save(tmp_path / "gp.png", Image.fromarray(g).convert("P"))
    img, info = load_image(tmp_path / "gp.png")
    assert img.shape == (4, 4, 3) and "palette expanded to RGB" in info.notes
    assert load_image(tmp_path / "gp.png", mode="grey").image.shape == (4, 4)


def test_palette_with_transparency(tmp_path):
    pal = Image.fromarray(rgb8(shape=(4, 4, 3))).convert("P")
    pil_save(tmp_path / "pt.png", pal, transparency=0)
    img, info = load_image(tmp_path / "pt.png")
    assert img.shape == (4, 4, 3) and info.had_alpha and "alpha channel dropped" in info.notes


def test_cmyk_jpeg_is_converted(tmp_path):
    pil_save(tmp_path / "c.jpg", Image.fromarray(rgb8(shape=(8, 8, 3))).convert("CMYK"))
    img, info = load_image(tmp_path / "c.jpg")
    assert img.shape == (8, 8, 3) and "CMYK converted to RGB" in info.notes


@pytest.mark.parametrize(
    "fmt, ext, kw",
    [("BMP", ".bmp", {}), ("WEBP", ".webp", {"lossless": True}), ("TIFF", ".tif", {}), ("PNG", ".png", {})],
)
def test_other_formats_load(tmp_path, fmt, ext, kw):
    a = rgb8(seed=4, shape=(7, 5, 3))
    pil_save(tmp_path / f"x{ext}", Image.fromarray(a), fmt, **kw)
    img, info = load_image(tmp_path / f"x{ext}")
    assert info.format == fmt
    np.testing.assert_array_equal(img, a / np.float32(255))


def test_animated_gif_gives_first_frame(tmp_path):
    red, blue = Image.new("RGB", (4, 3), (255, 0, 0)), Image.new("RGB", (4, 3), (0, 0, 255))
    red.save(tmp_path / "anim.gif", save_all=True, append_images=[blue], duration=100, loop=0)
    img, info = load_image(tmp_path / "anim.gif")
    assert info.format == "GIF" and img.shape == (3, 4, 3)
    np.testing.assert_array_equal(img[..., 0], 1.0)
    np.testing.assert_array_equal(img[..., 2], 0.0)
    assert "first frame of an animation used" in info.notes


def test_non_ascii_path(tmp_path):
    folder = tmp_path / "Ünïcödé 雪"
    folder.mkdir()
    path = folder / "текстура é.png"
    x = rng_image((4, 6, 3))
    save_image(path, x, recipe="{}")
    img, info = load_image(path)
    np.testing.assert_array_equal(img, np.rint(x * 255) / np.float32(255))
    assert info.path == str(path)
    assert read_recipe(path) == "{}"
    assert load_image(str(path)).image.shape == (4, 6, 3)


def test_modes(tmp_path):
    x = rng_image((4, 6, 3))
    save_image(tmp_path / "c.png", x)
    save_image(tmp_path / "g.png", x[..., 0])
    grey, info = load_image(tmp_path / "c.png", mode="grey")
    assert grey.shape == (4, 6) and info.channels == 1 and grey.flags.c_contiguous
    np.testing.assert_allclose(grey, luminance(load_image(tmp_path / "c.png").image), atol=1e-6)
    rgb, info = load_image(tmp_path / "g.png", mode="rgb")
    assert rgb.shape == (4, 6, 3) and info.channels == 3
    assert np.all(rgb == rgb[..., :1]) and "grey expanded to RGB" in info.notes
    assert load_image(tmp_path / "c.png", mode="rgb").image.shape == (4, 6, 3)
    assert load_image(tmp_path / "g.png", mode="grey").image.shape == (4, 6)
    with pytest.raises(InvalidParameter, match="mode"):
        load_image(tmp_path / "c.png", mode="RGB")


def test_info_is_frozen(tmp_path):
    save_image(tmp_path / "a.png", rng_image((2, 2)))
    info = load_image(tmp_path / "a.png").info
    assert isinstance(info, ImageInfo)
    with pytest.raises(dataclasses.FrozenInstanceError):
        info.width = 3  # type: ignore[misc]


# ----------------------------------------------------------------------------------------------
# EXIF orientation


def _asymmetric(h=4, w=6):
    a = np.zeros((h, w, 3), np.uint8)
    a[..., 0] = np.arange(w) * 40
    a[..., 1] = (np.arange(h) * 60)[:, None]
    a[0, 0] = (255, 255, 255)
    return a


@pytest.mark.parametrize("fmt, ext", [("PNG", ".png"), ("TIFF", ".tif"), ("WEBP", ".webp")])
@pytest.mark.parametrize("orientation", range(1, 9))
def test_exif_orientation_matches_pillow_and_opencv(tmp_path, monkeypatch, orientation, fmt, ext):
    src = Image.fromarray(_asymmetric())
    exif = Image.Exif()
    exif[0x0112] = orientation
    path = pil_save(tmp_path / f"o{ext}", src, fmt, exif=exif, lossless=True)
    img, info = load_image(path)
    expected = np.asarray(ImageOps.exif_transpose(Image.open(path)))
    np.testing.assert_array_equal(img, expected / np.float32(255))
    # OpenCV's own orientation handling (IMREAD_ANYDEPTH | IMREAD_ANYCOLOR) agrees
    bgr = cv2.imdecode(np.fromfile(path, np.uint8), cv2.IMREAD_ANYDEPTH | cv2.IMREAD_ANYCOLOR)
    np.testing.assert_array_equal(img, bgr[..., ::-1] / np.float32(255))
    assert info.orientation == orientation
    assert (f"EXIF orientation {orientation} applied" in info.notes) == (orientation != 1)
    assert (info.width, info.height) == ((4, 6) if orientation >= 5 else (6, 4))
    # the Pillow fallback applies it the same way
    monkeypatch.setattr(cv2, "imdecode", lambda *a, **k: None)
    again = load_image(path)
    np.testing.assert_array_equal(again.image, img)
    assert again.info == info


@pytest.mark.parametrize("fmt, ext", [("JPEG", ".jpg"), ("WEBP", ".webp"), ("TIFF", ".tif")])
def test_exif_orientation_6_rotates_other_formats(tmp_path, fmt, ext):
    src = np.zeros((40, 60, 3), np.uint8)
    src[:, :30] = (250, 250, 250)  # left half white
    exif = Image.Exif()
    exif[0x0112] = 6  # display = rotate 90 degrees clockwise
    path = pil_save(tmp_path / f"o{ext}", Image.fromarray(src), fmt, exif=exif, quality=95)
    img, info = load_image(path)
    assert img.shape == (60, 40, 3) and info.orientation == 6
    assert img[:25].mean() > 0.9 and img[35:].mean() < 0.1  # left became top


# ----------------------------------------------------------------------------------------------
# Recipes in PNG


@pytest.mark.parametrize(
    "recipe, chunk",
    [
        ('{"method": "quilt", "block": 32}', b"tEXt"),
        ("caf\u00e9 \u00b1 latin-1 only\nsecond line", b"tEXt"),
        ('{"name": "雪の織物 ✓ €"}', b"iTXt"),
    ],
)
def test_recipe_round_trip(tmp_path, recipe, chunk):
    x = rng_image((5, 4, 3))
    path = tmp_path / "r.png"
    save_image(path, x, recipe=recipe)
    data = path.read_bytes()
    assert data[12:16] == b"IHDR" and data[37:41] == chunk  # right after IHDR
    assert read_recipe(path) == recipe
    # still a valid PNG for OpenCV and Pillow
    bgr = cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_COLOR)
    np.testing.assert_array_equal(bgr[..., ::-1], np.rint(x * 255).astype(np.uint8))
    Image.open(path).verify()
    with Image.open(path) as im:
        im.load()
        assert im.text["weft-recipe"] == recipe
    np.testing.assert_array_equal(load_image(path).image, np.rint(x * 255) / np.float32(255))


def test_read_recipe_absent_or_not_png(tmp_path):
    save_image(tmp_path / "plain.png", rng_image((3, 3)))
    save_image(tmp_path / "r.jpg", rng_image((3, 3)), recipe="ignored for JPEG")
    (tmp_path / "t.txt").write_text("weft-recipe")
    assert read_recipe(tmp_path / "plain.png") is None
    assert read_recipe(tmp_path / "r.jpg") is None
    assert read_recipe(tmp_path / "t.txt") is None
    with pytest.raises(ImageError, match="no such file"):
        read_recipe(tmp_path / "missing.png")
    with pytest.raises(ImageError, match="is a directory"):
        read_recipe(tmp_path)


def test_read_recipe_written_by_pillow_compressed(tmp_path):
    from PIL import PngImagePlugin

    info = PngImagePlugin.PngInfo()
    info.add_itxt("weft-recipe", "ζ" * 500, zip=True)
    pil_save(tmp_path / "z.png", Image.new("RGB", (2, 2)), pnginfo=info)
    assert read_recipe(tmp_path / "z.png") == "ζ" * 500
    info = PngImagePlugin.PngInfo()
    info.add_text("other", "x")
    info.add_text("weft-recipe", "abc" * 100, zip=True)  # zTXt
    pil_save(tmp_path / "z2.png", Image.new("RGB", (2, 2)), pnginfo=info)
    assert read_recipe(tmp_path / "z2.png") == "abc" * 100


def test_read_recipe_skips_chunk_with_bad_crc(tmp_path):
    save_image(tmp_path / "r.png", rng_image((3, 3)), recipe="good")
    data = bytearray((tmp_path / "r.png").read_bytes())
    data[47] ^= 0xFF  # inside the tEXt data
    (tmp_path / "bad.png").write_bytes(bytes(data))
    assert read_recipe(tmp_path / "bad.png") is None


# ----------------------------------------------------------------------------------------------
# Saving and atomic writes


def test_save_refuses_unknown_extension(tmp_path):
    for name in ("a.gif", "a.bmp", "noext"):
        with pytest.raises(ImageError) as e:
            save_image(tmp_path / name, rng_image((2, 2)))
        assert ".png" in str(e.value) and ".jpg" in str(e.value) and ".tiff" in str(e.value)
        assert_one_line_error(e, tmp_path / name)
    assert list(tmp_path.iterdir()) == []


def test_save_refuses_16bit_jpeg_and_bad_parameters(tmp_path):
    with pytest.raises(ImageError, match="JPEG.*16-bit"):
        save_image(tmp_path / "a.jpg", rng_image((2, 2)), bit_depth=16)
    for kw in (
        {"bit_depth": 12},
        {"bit_depth": True},
        {"quality": 101},
        {"quality": -1},
        {"quality": 9.5},
        {"recipe": b"bytes"},
        {"recipe": "nul\0inside"},
    ):
        with pytest.raises(InvalidParameter):
            save_image(tmp_path / "a.png", rng_image((2, 2)), **kw)
    with pytest.raises(ImageError, match="NaN"):
        save_image(tmp_path / "a.png", np.full((2, 2), np.nan, np.float32))
    assert list(tmp_path.iterdir()) == []


def test_encoder_failure_is_an_image_error(tmp_path, monkeypatch):
    monkeypatch.setattr(cv2, "imencode", lambda *a, **k: (False, None))
    with pytest.raises(ImageError, match=r"a\.png: cannot encode PNG \(the encoder failed\)"):
        save_image(tmp_path / "a.png", rng_image((2, 2)))

    def boom(*args, **kwargs):
        raise cv2.error("simulated")

    monkeypatch.setattr(cv2, "imencode", boom)
    with pytest.raises(ImageError, match="simulated"):
        save_image(tmp_path / "a.jpg", rng_image((2, 2)))
    assert list(tmp_path.iterdir()) == []


def test_save_into_missing_folder(tmp_path):
    with pytest.raises(ImageError) as e:
        save_image(tmp_path / "nope" / "a.png", rng_image((2, 2)))
    assert "does not exist" in str(e.value)
    assert_one_line_error(e, tmp_path / "nope" / "a.png")


def test_save_accepts_uint8(tmp_path):
    a = rgb8(shape=(3, 4, 3))
    save_image(tmp_path / "u.png", a)
    np.testing.assert_array_equal(np.asarray(Image.open(tmp_path / "u.png")), a)


def test_atomic_write_failure_keeps_old_file_and_no_temp(tmp_path, monkeypatch):
    target = tmp_path / "out.png"
    save_image(target, rng_image((4, 4, 3), seed=1))
    old = target.read_bytes()

    def fail(*args, **kwargs):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(os, "replace", fail)
    with pytest.raises(ImageError) as e:
        save_image(target, rng_image((4, 4, 3), seed=2))
    assert str(e.value) == f"{target}: cannot write (No space left on device)"
    assert target.read_bytes() == old
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.png"]
    with pytest.raises(ImageError):
        atomic_write_bytes(tmp_path / "new.json", b"{}")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.png"]


def test_atomic_write_failure_during_write(tmp_path, monkeypatch):
    target = tmp_path / "r.json"
    target.write_bytes(b"old")
    monkeypatch.setattr(os, "fsync", lambda fd: (_ for _ in ()).throw(OSError(5, "Input/output error")))
    with pytest.raises(ImageError, match="Input/output error"):
        atomic_write_bytes(target, b"new")
    assert target.read_bytes() == b"old"
    assert [p.name for p in tmp_path.iterdir()] == ["r.json"]


def test_atomic_write_modes_and_overwrite(tmp_path):
    new = tmp_path / "new.bin"
    atomic_write_bytes(new, b"1")
    mask = os.umask(0)
    os.umask(mask)
    assert new.stat().st_mode & 0o777 == 0o666 & ~mask  # not mkstemp's 0o600
    new.chmod(0o640)
    atomic_write_bytes(new, b"22")
    assert new.read_bytes() == b"22" and new.stat().st_mode & 0o777 == 0o640
    with pytest.raises(ImageError, match="cannot write"):
        atomic_write_bytes(tmp_path, b"x")  # a directory
    with pytest.raises(ImageError, match="does not exist"):
        atomic_write_bytes(tmp_path / "missing" / "x", b"x")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["new.bin"]


def test_params_can_use_atomic_write():
    from weft.core import params

    assert params is not None and ci.atomic_write_bytes is atomic_write_bytes


# ----------------------------------------------------------------------------------------------
# Pixel limit and decompression bombs


def _bomb_png(path, width=60000, height=60000):
    ok, buf = cv2.imencode(".png", np.zeros((1, 1), np.uint8))
    data = bytearray(buf.tobytes())
    assert data[12:16] == b"IHDR"
    data[16:24] = struct.pack(">II", width, height)
    data[29:33] = struct.pack(">I", zlib.crc32(bytes(data[12:29])))
    path.write_bytes(bytes(data))
    return path


def test_decompression_bomb_refused_from_header(tmp_path, monkeypatch):
    path = _bomb_png(tmp_path / "big.png")

    def must_not_decode(*args, **kwargs):
        raise AssertionError("pixels were decoded")

    monkeypatch.setattr(cv2, "imdecode", must_not_decode)
    monkeypatch.setattr(np, "fromfile", must_not_decode)
    monkeypatch.setattr(ci.files, "_decode_pillow", must_not_decode)
    before = Image.MAX_IMAGE_PIXELS
    with pytest.raises(ImageError) as e:
        load_image(path)
    assert str(e.value) == (
        f"{path}: 60000x60000 = 3600.0 megapixels exceeds the limit of 50 megapixels "
        "(set WEFT_MAX_PIXELS or max_pixels to raise it)"
    )
    assert_one_line_error(e, path)
    assert Image.MAX_IMAGE_PIXELS == before  # Pillow's own setting restored


def test_max_pixels_argument(tmp_path):
    path = tmp_path / "a.png"
    save_image(path, rng_image((10, 10)))
    assert load_image(path, max_pixels=100).image.shape == (10, 10)
    with pytest.raises(ImageError, match="megapixels"):
        load_image(path, max_pixels=99)
    for bad in (0, -5, 1.5, True, "100"):
        with pytest.raises(InvalidParameter, match="max_pixels"):
            load_image(path, max_pixels=bad)


def test_max_pixels_env_var_and_setter(tmp_path, monkeypatch):
    path = tmp_path / "a.png"
    save_image(path, rng_image((10, 10)))
    assert get_max_pixels() == DEFAULT_MAX_PIXELS == 50_000_000
    monkeypatch.setenv("WEFT_MAX_PIXELS", "99")
    assert get_max_pixels() == 99
    with pytest.raises(ImageError, match="limit of 9.9e-05 megapixels"):
        load_image(path)
    assert load_image(path, max_pixels=100).image.shape == (10, 10)  # argument wins
    set_max_pixels(1000)
    assert get_max_pixels() == 1000 and load_image(path).image.shape == (10, 10)
    set_max_pixels(None)
    assert get_max_pixels() == 99
    for invalid in ("lots", "0", "-3", ""):
        monkeypatch.setenv("WEFT_MAX_PIXELS", invalid)
        assert get_max_pixels() == DEFAULT_MAX_PIXELS
    monkeypatch.setenv("WEFT_MAX_PIXELS", "200_000_000")
    assert get_max_pixels() == 200_000_000
    for bad in (0, -1, 2.5, False):
        with pytest.raises(InvalidParameter):
            set_max_pixels(bad)


def test_bomb_within_raised_limit_reaches_decoder(tmp_path):
    # a lying header with a generous limit must fail cleanly, not crash or return garbage
    path = _bomb_png(tmp_path / "liar.png", 3000, 3000)
    with pytest.raises(ImageError) as e:
        load_image(path)
    assert "truncated or corrupt PNG" in str(e.value)
    assert_one_line_error(e, path)


# ----------------------------------------------------------------------------------------------
# Broken inputs


def _truncated(tmp_path, ext, fraction):
    full = tmp_path / f"full{ext}"
    pil_save(full, Image.fromarray(rgb8(shape=(64, 64, 3))))
    data = full.read_bytes()
    path = tmp_path / f"cut{ext}"
    path.write_bytes(data[: int(len(data) * fraction)])
    return path


def _directory(d):
    (d / "dir.png").mkdir()
    return d / "dir.png"


def _file(name, content):
    def make(d):
        (d / name).write_bytes(content)
        return d / name

    return make


BROKEN = {
    "missing": (lambda d: d / "missing.png", "no such file"),
    "directory": (_directory, "is a directory"),
    "empty": (_file("empty.png", b""), "empty file"),
    "text": (_file("notes.png", b"hello, not a png\n"), "not an image file (cannot identify format)"),
    "signature only": (_file("sig.png", b"\x89PNG\r\n\x1a\n"), "truncated or corrupt PNG data"),
    "truncated png": (lambda d: _truncated(d, ".png", 0.5), "truncated or corrupt PNG data"),
    "truncated png header": (lambda d: _truncated(d, ".png", 0.02), "truncated or corrupt PNG data"),
    "truncated jpeg": (lambda d: _truncated(d, ".jpg", 0.5), "truncated or corrupt JPEG data"),
    "truncated jpeg late": (lambda d: _truncated(d, ".jpg", 0.97), "truncated or corrupt JPEG data"),
    "truncated tiff": (lambda d: _truncated(d, ".tif", 0.5), "truncated or corrupt TIFF data"),
    "truncated webp": (lambda d: _truncated(d, ".webp", 0.5), "truncated or corrupt WEBP data"),
}


@pytest.mark.parametrize("case", BROKEN)
def test_broken_inputs_give_one_line_image_error(tmp_path, case):
    make, expected = BROKEN[case]
    path = make(tmp_path)
    with pytest.raises(ImageError) as e:
        load_image(path)
    assert expected in str(e.value)
    assert_one_line_error(e, path)
    assert isinstance(e.value, WeftError) and isinstance(e.value, ValueError)


def test_permission_denied(tmp_path, monkeypatch):
    path = tmp_path / "secret.png"
    save_image(path, rng_image((2, 2)))

    def denied(*args, **kwargs):
        raise PermissionError(13, "Permission denied")

    monkeypatch.setattr(Image, "open", denied)
    with pytest.raises(ImageError) as e:
        load_image(path)
    assert str(e.value) == f"{path}: permission denied"


def test_read_error_after_header(tmp_path, monkeypatch):
    path = tmp_path / "a.png"
    save_image(path, rng_image((2, 2)))
    monkeypatch.setattr(np, "fromfile", lambda *a, **k: (_ for _ in ()).throw(OSError(5, "Input/output error")))
    with pytest.raises(ImageError, match=r"a\.png: cannot read \(Input/output error\)"):
        load_image(path)


@pytest.mark.parametrize("kind", ["rgb", "grey", "rgba", "la", "palette", "grey16", "gif"])
def test_pillow_fallback_matches_opencv(tmp_path, monkeypatch, kind):
    a = rgb8(seed=7, shape=(5, 6, 3))
    pim = {
        "rgb": Image.fromarray(a),
        "grey": Image.fromarray(a[..., 0]),
        "rgba": Image.fromarray(np.dstack([a, a[..., :1]]), "RGBA"),
        "la": Image.fromarray(a[..., :2], "LA"),
        "palette": Image.fromarray(a).convert("P"),
        "grey16": Image.fromarray(a[..., 0].astype(np.uint16) * 257),
        "gif": Image.fromarray(a).convert("P"),
    }[kind]
    path = pil_save(tmp_path / ("x.gif" if kind == "gif" else "x.png"), pim)
    via_cv2 = load_image(path)
    monkeypatch.setattr(cv2, "imdecode", lambda *a, **k: None)
    via_pil = load_image(path)
    np.testing.assert_array_equal(via_pil.image, via_cv2.image)
    assert via_pil.info == via_cv2.info


def test_opencv_exception_falls_back_to_pillow(tmp_path, monkeypatch):
    save_image(tmp_path / "a.png", rng_image((3, 3, 3)))
    expected = load_image(tmp_path / "a.png").image

    def boom(*args, **kwargs):
        raise cv2.error("simulated")

    monkeypatch.setattr(cv2, "imdecode", boom)
    np.testing.assert_array_equal(load_image(tmp_path / "a.png").image, expected)


def test_unexpected_decoder_output_is_an_image_error(tmp_path, monkeypatch):
    save_image(tmp_path / "a.png", rng_image((3, 3)))
    monkeypatch.setattr(cv2, "imdecode", lambda *a, **k: np.zeros((3, 3), np.float64))
    with pytest.raises(ImageError, match="unsupported sample type float64"):
        load_image(tmp_path / "a.png")
    monkeypatch.setattr(cv2, "imdecode", lambda *a, **k: np.zeros((3, 3, 3, 3), np.uint8))
    with pytest.raises(ImageError, match=r"a\.png: cannot decode PNG data"):
        load_image(tmp_path / "a.png")


def test_float_tiff_is_refused(tmp_path):
    pil_save(tmp_path / "f.tif", Image.fromarray(np.zeros((3, 3), np.float32)))
    with pytest.raises(ImageError, match="only 8- and 16-bit"):
        load_image(tmp_path / "f.tif")


# ----------------------------------------------------------------------------------------------
# validate_image


def test_validate_image_conversions():
    a8 = np.array([[0, 128, 255]], np.uint8)
    np.testing.assert_allclose(validate_image(a8), [[0, 128 / 255, 1]], rtol=1e-6)
    a16 = np.array([[0, 65535]], np.uint16)
    np.testing.assert_array_equal(validate_image(a16), [[0, 1]])
    f64 = np.random.default_rng(0).random((4, 5, 3))
    out = validate_image(f64)
    assert out.dtype == np.float32 and out.flags.c_contiguous
    f32 = f64.astype(np.float32)
    assert validate_image(f32) is f32  # no copy when already fine
    strided = f32[:, ::2]
    out = validate_image(strided)
    assert out.flags.c_contiguous and np.array_equal(out, strided)
    assert validate_image(np.zeros((1, 1), np.float16)).dtype == np.float32
    assert validate_image(np.ones((2, 2))).max() == 1.0


@pytest.mark.parametrize(
    "bad, expected",
    [
        (np.full((2, 2), np.nan, np.float32), "NaN"),
        (np.full((2, 2), np.inf), "infinite"),
        (np.full((2, 2), -0.01), "outside [0, 1]"),
        (np.full((2, 2, 3), 1.5), "outside [0, 1]"),
        (np.zeros((2, 2, 4)), "shape"),
        (np.zeros((2, 2, 1)), "shape"),
        (np.zeros(5), "shape"),
        (np.zeros((1, 2, 3, 3)), "shape"),
        (np.zeros((0, 5)), "empty"),
        (np.zeros((2, 2), np.int32), "dtype"),
        (np.zeros((2, 2), bool), "dtype"),
        (np.zeros((2, 2), np.complex64), "dtype"),
    ],
)
def test_validate_image_rejects(bad, expected):
    with pytest.raises(ImageError) as e:
        validate_image(bad, what="texture")
    msg = str(e.value)
    assert msg.startswith("texture") and expected in msg and "\n" not in msg


@given(hnp.arrays(np.uint8, hnp.array_shapes(min_dims=2, max_dims=2, max_side=8)))
def test_validate_uint8_property(a):
    out = validate_image(a)
    assert out.dtype == np.float32 and out.shape == a.shape
    np.testing.assert_array_equal(np.rint(out * 255).astype(np.uint8), a)


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(
    hnp.arrays(np.uint16, st.tuples(st.integers(1, 6), st.integers(1, 6), st.sampled_from([3]))),
    st.sampled_from([".png", ".tif"]),
)
def test_16bit_round_trip_property(tmp_path, a, ext):
    path = tmp_path / f"p{ext}"
    save_image(path, a, bit_depth=16)
    out = load_image(path).image
    np.testing.assert_array_equal(np.rint(out.astype(np.float64) * 65535).astype(np.uint16), a)


# ----------------------------------------------------------------------------------------------
# resize


def test_resize_shapes_and_interpolations():
    x = rng_image((10, 20, 3))
    for interp in ("cubic", "linear", "area", "nearest"):
        out = resize(x, (7, 5), interpolation=interp)
        assert out.shape == (5, 7, 3) and out.dtype == np.float32
    assert resize(x[..., 0], (40, 30)).shape == (30, 40)


def test_resize_cubic_is_clipped():
    checker = (np.indices((8, 8)).sum(axis=0) % 2).astype(np.float32)
    up = resize(checker, (33, 33), interpolation="cubic")
    assert up.min() >= 0.0 and up.max() <= 1.0
    raw = cv2.resize(checker, (33, 33), interpolation=cv2.INTER_CUBIC)
    assert raw.min() < 0.0 or raw.max() > 1.0  # the clip mattered


def test_resize_nearest_and_area_exact():
    x = rng_image((4, 6))
    np.testing.assert_array_equal(resize(x, (12, 8), "nearest"), np.repeat(np.repeat(x, 2, 0), 2, 1))
    big = rng_image((8, 12, 3))
    expected = big.reshape(4, 2, 6, 2, 3).mean(axis=(1, 3))
    np.testing.assert_allclose(resize(big, (6, 4), "area"), expected, atol=1e-6)
    assert resize(np.zeros((4, 4), np.uint8) + 255, (2, 2)).max() == pytest.approx(1.0)


@pytest.mark.parametrize("size", [(0, 5), (5,), (5, -1), (2.5, 3), "10x10", (True, 3), None])
def test_resize_rejects_bad_size(size):
    with pytest.raises(InvalidParameter, match="size"):
        resize(rng_image((4, 4)), size)


def test_resize_rejects_bad_interpolation_and_image():
    with pytest.raises(InvalidParameter, match="interpolation"):
        resize(rng_image((4, 4)), (2, 2), interpolation="lanczos")
    with pytest.raises(ImageError):
        resize(np.full((4, 4), 2.0), (2, 2))


# ----------------------------------------------------------------------------------------------
# Colour helpers


def test_luminance_weights():
    primaries = np.eye(3, dtype=np.float32)[None]  # 1 x 3 pixels: R, G, B
    np.testing.assert_allclose(luminance(primaries), [[0.299, 0.587, 0.114]], rtol=1e-6)
    np.testing.assert_allclose(luminance(np.ones((2, 2, 3), np.float32)), 1.0, rtol=1e-6)
    g = rng_image((3, 4))
    np.testing.assert_array_equal(luminance(g), g)
    assert luminance(rng_image((3, 4, 3))).shape == (3, 4)
    with pytest.raises(ImageError):
        luminance(np.zeros((3, 4, 2)))


def test_yiq_round_trip_and_ranges():
    x = rng_image((16, 16, 3), seed=5)
    yiq = rgb_to_yiq(x)
    assert yiq.dtype == np.float32 and yiq.shape == x.shape
    np.testing.assert_allclose(yiq[..., 0], luminance(x), atol=1e-6)
    np.testing.assert_allclose(yiq_to_rgb(yiq), x, atol=1e-5)
    white = rgb_to_yiq(np.ones((1, 1, 3), np.float32))
    np.testing.assert_allclose(white[0, 0], [1, 0, 0], atol=1e-5)  # grey has no chroma
    assert np.abs(yiq[..., 1]).max() <= 0.5958 and np.abs(yiq[..., 2]).max() <= 0.5232
    out_of_gamut = np.array([[[0.5, 0.6, 0.0]]], np.float32)  # large I
    assert yiq_to_rgb(out_of_gamut).max() <= 1.0
    assert yiq_to_rgb(out_of_gamut, clip=False).max() > 1.0
    with pytest.raises(ImageError):
        rgb_to_yiq(rng_image((3, 3)))
    with pytest.raises(ImageError):
        yiq_to_rgb(rng_image((3, 3)))


def test_pca_grey_recovers_single_colour_direction():
    direction = np.array([0.6, 0.3, 0.1])
    direction /= np.linalg.norm(direction)
    t = np.random.default_rng(2).uniform(-0.4, 0.4, (20, 30))
    base = np.array([0.45, 0.5, 0.55])
    rgb = (base + t[..., None] * direction).astype(np.float32)
    grey, basis = pca_grey(rgb)
    assert grey.shape == (20, 30) and grey.dtype == np.float32
    np.testing.assert_allclose(basis.axes[0], direction, atol=1e-4)  # sign: positive with luminance
    np.testing.assert_allclose(basis.axes @ basis.axes.T, np.eye(3), atol=1e-5)
    assert basis.variances[0] > 1e3 * max(basis.variances[1], 1e-12)
    offset = float(basis.mean @ basis.axes[0])
    np.testing.assert_allclose(grey - offset, t - t.mean(), atol=1e-4)
    comps, same = to_pca(rgb, basis)
    assert same is basis
    np.testing.assert_allclose(from_pca(comps, basis), rgb, atol=1e-6)
    np.testing.assert_allclose(comps[..., 0], grey - offset, atol=1e-6)
    rebuilt = from_pca(np.stack([grey - offset, comps[..., 1], comps[..., 2]], axis=-1), basis)
    np.testing.assert_allclose(rebuilt, rgb, atol=1e-6)


def test_pca_round_trip_general_and_flat():
    x = rng_image((9, 9, 3), seed=8)
    comps, basis = to_pca(x)
    np.testing.assert_allclose(from_pca(comps, basis), x, atol=1e-6)
    assert list(basis.variances) == sorted(basis.variances, reverse=True)
    flat = np.full((4, 4, 3), 0.3, np.float32)
    grey, basis = pca_grey(flat)
    luma = np.array([0.299, 0.587, 0.114])
    np.testing.assert_allclose(basis.axes[0], luma / np.linalg.norm(luma), atol=1e-6)
    assert np.ptp(grey) == 0
    with pytest.raises(ImageError):
        pca_grey(rng_image((3, 3)))


def test_luminance_correlated_sign():
    # a dark-to-bright ramp: the first axis must point towards brightness
    t = np.linspace(0, 1, 50, dtype=np.float32)[None, :, None]
    rgb = np.broadcast_to(t, (2, 50, 3)).copy()
    grey, basis = pca_grey(rgb)
    assert basis.axes[0] @ np.array([0.299, 0.587, 0.114]) > 0
    assert np.all(np.diff(grey[0]) > 0)


def test_module_has_no_bgr_leak(tmp_path):
    # saving RGB and reading with Pillow (RGB) and our loader agree channel by channel
    a = rgb8(seed=9, shape=(3, 5, 3))
    save_image(tmp_path / "c.tif", a)
    np.testing.assert_array_equal(np.asarray(Image.open(tmp_path / "c.tif")), a)
    np.testing.assert_array_equal(load_image(tmp_path / "c.tif").image, a / np.float32(255))


def _png16_with_trns(path, samples: np.ndarray, key: tuple[int, ...]) -> None:
    """A 16-bit grey (colour type 0) or RGB (type 2) PNG whose transparency is a tRNS colour key."""

    def chunk(kind: bytes, body: bytes) -> bytes:
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body) & 0xFFFFFFFF)

    h, w = samples.shape[:2]
    colour_type = 0 if samples.ndim == 2 else 2
    raw = b"".join(b"\0" + samples[y].astype(">u2").tobytes() for y in range(h))
    Path(path).write_bytes(
        b"\x89PNG\r\n\x1a\n"
        + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 16, colour_type, 0, 0, 0))
        + chunk(b"tRNS", struct.pack(f">{len(key)}H", *key))
        + chunk(b"IDAT", zlib.compress(raw))
        + chunk(b"IEND", b"")
    )


@pytest.mark.parametrize("colour", [False, True], ids=["grey", "rgb"])
def test_a_16_bit_png_whose_transparency_is_a_trns_key_keeps_it(tmp_path, colour):
    rng = np.random.default_rng(3)
    samples = rng.integers(1000, 65000, size=(6, 7, 3) if colour else (6, 7)).astype(np.uint16)
    key = (777, 4242, 65535) if colour else (777,)
    samples[1:3, 2:5] = key if colour else key[0]
    _png16_with_trns(tmp_path / "k.png", samples, key)
    img, info = load_image(tmp_path / "k.png", alpha=True)
    assert info.bit_depth == 16 and info.had_alpha and img.shape == (6, 7, 4 if colour else 2)
    expected_alpha = np.ones((6, 7), np.float32)
    expected_alpha[1:3, 2:5] = 0.0
    np.testing.assert_array_equal(img[..., -1], expected_alpha)
    np.testing.assert_array_equal(img[..., :-1], (samples if colour else samples[..., None]) / np.float32(65535))
    flat, flat_info = load_image(tmp_path / "k.png")  # without alpha: the colours, 16-bit, alpha dropped
    assert flat.shape == samples.shape and flat_info.bit_depth == 16 and "alpha channel dropped" in flat_info.notes
