"""The bundled example images in ``resources/`` (see ``resources/README.md`` for their sources)."""

from __future__ import annotations

from pathlib import Path

from .errors import WeftError

RESOURCES = Path(__file__).resolve().parent.parent / "resources"
IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".tif", ".tiff", ".bmp", ".webp")


def examples() -> list[Path]:
    """Paths of the bundled example images, sorted by name (empty if the folder is missing)."""
    if not RESOURCES.is_dir():
        return []
    return sorted(p for p in RESOURCES.iterdir() if p.suffix.lower() in IMAGE_SUFFIXES and p.is_file())


def example(name: str) -> Path:
    """The bundled example called ``name`` (with or without extension).

    Parameters
    ----------
    name : str
        The file name or its stem, e.g. ``"brick"`` or ``"brick.png"``.

    Returns
    -------
    pathlib.Path
        The example's file under ``resources/``.

    Raises
    ------
    WeftError
        No example has that name; the message lists the known ones.
    """
    for p in examples():
        if p.name == name or p.stem == name:
            return p
    known = ", ".join(p.stem for p in examples()) or "none (resources/ is missing)"
    raise WeftError(f"no bundled example named {name!r} (known: {known})")
