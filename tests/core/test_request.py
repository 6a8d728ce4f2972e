"""The render request (weft.core.request): files, images or a builder give the same pixels, one crop to
the source region, a preview's reduction, and errors that name the file (Qt-free)."""

import numpy as np
import pytest
from weft.core import registry
from weft.core.errors import InvalidParameter, WeftError
from weft.core.geometry import Square
from weft.core.image import load_image, save_image
from weft.core.request import FULL, Preview, RenderRequest


@pytest.fixture
def files(tmp_path):
    rng = np.random.default_rng(3)
    texture = rng.random((48, 56, 3)).astype(np.float32)
    target = rng.random((40, 64, 3)).astype(np.float32)
    paths = {"texture": str(tmp_path / "t.png"), "target": str(tmp_path / "g.png")}
    save_image(paths["texture"], texture)
    save_image(paths["target"], target)
    images = {name: load_image(path).image for name, path in paths.items()}
    return paths, images


def test_files_images_and_a_builder_render_the_same_pixels_cropped_to_the_region(files):
    paths, images = files
    fast = registry.get("fast")
    region = Square(4, 6, 30)
    from_files = RenderRequest(fast, fast.params(), paths, 5, region).run()
    from_images = RenderRequest(fast, fast.params(), images, 5, region).run()
    built = []
    from_builder = RenderRequest(fast, fast.params(), lambda names=None: built.append(names) or dict(images), 5, region)
    out = from_builder.run()
    assert built == [None]  # built once, when run
    assert np.array_equal(from_files.image, from_images.image) and np.array_equal(from_files.image, out.image)
    # the region crop is what the method ran on: the same as cropping the texture first
    cropped = dict(images, texture=images["texture"][6:36, 4:34])
    direct = fast.run(cropped, fast.params(), rng=5)
    assert np.array_equal(out.image, direct.image)
    assert from_files.infos["texture"].bit_depth == 8 and from_images.infos == {}
    assert out.request is from_builder and out.seconds >= 0 and out.figures == dict(direct.figures)


def test_a_region_outside_the_texture_is_one_clear_error(files):
    paths, _ = files
    fast = registry.get("fast")
    with pytest.raises(InvalidParameter) as caught:
        RenderRequest(fast, fast.params(), paths, 1, Square(40, 0, 30)).run()
    assert str(caught.value) == "parameter 'region' = 40,0,30 leaves the texture (56x48)"


def test_a_file_too_small_is_named(files, tmp_path):
    paths, images = files
    fast = registry.get("fast")
    small = tmp_path / "small.png"
    save_image(small, images["texture"][:2, :2])
    with pytest.raises(WeftError) as caught:
        RenderRequest(fast, fast.params(), dict(paths, texture=str(small)), 1).run()
    assert str(caught.value).startswith(f"{small}: the texture is 2x2")


def test_a_preview_is_reduced_as_the_method_says_and_prepared_once(files):
    _, images = files
    fast = registry.get("fast")
    big = dict(images, target=np.repeat(np.repeat(images["target"], 4, axis=0), 4, axis=1))  # 160x256
    request = RenderRequest(fast, fast.params(), big, 2, mode=Preview(64))
    prepared = request.prepared()
    assert prepared.images["target"].shape == (40, 64, 3) and prepared.images["texture"] is big["texture"]
    preview = request.run()
    assert preview.image.shape[:2] == (40, 64)
    full = RenderRequest(fast, fast.params(), big, 2, mode=FULL).run()
    assert full.image.shape[:2] == (160, 256)
