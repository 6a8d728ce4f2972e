"""A session reads and writes itself, its masks included (``weft.core.session.Session``)."""

import json

import numpy as np
from weft.core import registry
from weft.core.geometry import Mask, Square
from weft.core.session import Session, mask_file


def _mask(w=40, h=30) -> Mask:
    return Mask.empty(w, h).painted_line((5, 5), (30, 20), 3)


def test_a_saved_session_reads_back_equal_with_its_mask(tmp_path):
    picture = tmp_path / "pics" / "brick.png"
    session = Session(
        method="fill",
        params={"fast": registry.get("fast").params(p=0.4)},
        inputs={"image": str(picture)},
        geometry={"fill": {"mask": _mask()}, "affine": {"prototype": Square(5, 6, 20)}},
        seed=7,
        opened_for={"image": "fill"},
    )
    path = tmp_path / "s.weft.json"
    session.save(path)
    assert mask_file(path, "fill", "mask").is_file()
    data = json.loads(path.read_text())
    assert data["inputs"] == {"image": "pics/brick.png"}  # relative to the session's folder
    assert data["geometry"]["fill"]["mask"] == "s.weft.fill.mask.png"
    again = Session.read(path)
    assert again == session
    assert np.array_equal(again.geometry["fill"]["mask"].bits, _mask().bits)


def test_a_session_written_with_absolute_paths_names_where_it_was_saved(tmp_path):
    session = Session(method="fill", inputs={"image": "rel/brick.png"}, geometry={"fill": {"mask": _mask()}})
    path = tmp_path / "recovery.weft.json"
    files = session.files(path, relative=False)
    assert list(files) == [mask_file(path, "fill", "mask"), path]  # the mask first: the JSON names it
    data = json.loads(files[path])
    assert data["geometry"]["fill"]["mask"] == str(mask_file(path, "fill", "mask"))
    assert data["inputs"]["image"].startswith("/") and data["inputs"]["image"].endswith("rel/brick.png")
    saved = Session(method="fill", saved_as=str(tmp_path / "mine.weft.json"))
    saved.save(path, relative=False)
    assert Session.read(path).saved_as == str(tmp_path / "mine.weft.json")


def test_a_session_in_the_format_written_before_the_session_value_still_opens(tmp_path):
    """The JSON and mask PNG the studio wrote before sessions wrote themselves (its document's
    session_dict and its mask's save) read into the same values."""
    mask = _mask()
    mask.save(tmp_path / "old.weft.fill.mask.png")
    (tmp_path / "old.weft.json").write_text(
        json.dumps(
            {
                "weft_session": 1,
                "method": "fill",
                "params": {"fill": {"engine": "auto", "band": 3}},
                "inputs": {"image": "brick.png", "texture": "../wood.png"},
                "opened_for": {},
                "geometry": {"affine": {"prototype": [5, 6, 20]}, "fill": {"mask": "old.weft.fill.mask.png"}},
                "seed": 42,
            },
            indent=1,
        )
    )
    session = Session.read(tmp_path / "old.weft.json")
    assert (session.method, session.seed, session.params["fill"].band) == ("fill", 42, 3)
    assert session.inputs == {"image": str(tmp_path / "brick.png"), "texture": str(tmp_path / ".." / "wood.png")}
    assert session.geometry["affine"] == {"prototype": Square(5, 6, 20)}
    assert session.geometry["fill"]["mask"] == mask and session.opened_for == {} and session.saved_as is None
