"""One item: a method run on image files, and the recipe its output carries.

``weft METHOD``, ``weft run`` and every item of a batch (:mod:`weft.core.batch`) go through these same
functions, so a batch output is byte for byte what ``weft run`` gives for that item's recipe:

* :func:`load_recipe` reads a recipe (``.json``, or a PNG exported by weft) and
  :func:`check_recipe` validates it against its method (inputs it takes, parameters; geometry that
  names a file, as older recipes' ``"lines": "L.json"``, is read there, relative to the recipe);
* :func:`output_recipe` is the recipe an output at a given path carries (paths relative to its folder);
* a :class:`~weft.core.request.RenderRequest` with the input files loads them, checks their sizes,
  runs the method and names the file behind an error about one input; the caller encodes or saves
  the result with the recipe (:func:`weft.core.image.save_image` / :func:`weft.core.image.encode_image`).
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Mapping
from pathlib import Path

from .errors import WeftError
from .geometry import Square
from .params import Params, Recipe, relative_path
from .readfile import kind_of, open_regular, shown


def load_recipe(path: str) -> Recipe:
    """A recipe from a ``.json`` file or from the ``weft-recipe`` chunk of a PNG weft exported; its
    relative input paths are resolved against the file's folder. One-line ``WeftError`` naming the
    file; an image of another format is told that only PNG exports (and ``.json`` files) carry a recipe."""
    from .image import read_recipe
    from .image.files import _SIGNATURES

    p = Path(path)
    name = shown(path)
    if not p.exists():
        raise WeftError(f"{name}: no such file")
    head = b""
    with contextlib.suppress(OSError, WeftError), open_regular(p, "recipe file") as f:
        head = f.read(8)
    if head.startswith(b"\x89PNG"):
        text = read_recipe(p)
        if text is None:
            raise WeftError(f"{name}: this PNG carries no weft recipe (only PNGs exported by weft do)")
        try:
            return Recipe.from_json(text, base=p.resolve().parent)
        except WeftError as e:
            raise WeftError(f"{name}: {e}") from None
    fmt = next((fmt for magic, fmt in _SIGNATURES.items() if head.startswith(magic)), None)
    if fmt is not None:
        raise WeftError(
            f"{name}: a {fmt} image carries no recipe; only PNGs exported by weft (and .json recipe files) do"
        )
    return Recipe.load(p)


def check_recipe(recipe: Recipe, base: Path, *, supplied: tuple[str, ...] = ()) -> dict:
    """Validate ``recipe`` against its method before any image is read; returns its parameters in
    their JSON form with every geometry inline (one that names a file is read relative to ``base``,
    the recipe file's folder, never the current one).

    ``supplied`` names inputs given from elsewhere (a batch's ``--over``): they need not be in the
    recipe, nor exist. Messages do not name the recipe file; the caller puts it in front.
    """
    from . import registry

    method = registry.get(recipe.method)
    takes = [i.name for i in method.inputs]
    unknown = sorted(set(recipe.inputs) - set(takes))
    if unknown:
        raise WeftError(
            f"recipe names input {', '.join(map(repr, unknown))}, which {method.name} does not "
            f"take (it takes {', '.join(takes)})"
        )
    missing = [i.name for i in method.inputs if i.required and i.name not in recipe.inputs and i.name not in supplied]
    if missing:
        raise WeftError(f"recipe names no {', '.join(missing)} image for {method.name}")
    params = method.params.from_dict(recipe.params, base=base)
    for name, path in recipe.inputs.items():
        if name not in supplied and not os.path.exists(path):
            raise WeftError(f"the {name} image {shown(path)} does not exist")
        if name not in supplied and (kind := kind_of(os.stat(path).st_mode)) is not None:
            raise WeftError(f"the {name} image {shown(path)} is {kind}, not an image file")
    return params.to_dict()


def output_recipe(
    method,
    params: Params,
    input_paths: Mapping[str, str],
    seed: int,
    region: tuple[int, int, int] | None,
    out: str | os.PathLike,
) -> Recipe:
    """The recipe a run's output at ``out`` carries: input paths relative to the output's folder
    (``weft run OUT.png`` then finds them wherever the folder moves); geometry (feature lines, a view)
    inline, so it needs no other file."""
    out_dir = Path(out).resolve().parent
    rel_inputs = {name: relative_path(path, out_dir) for name, path in input_paths.items()}
    return Recipe(
        method=method.name,
        params=params.to_dict(),
        inputs=rel_inputs,
        seed=seed,
        region=None if region is None else Square._make(region),
    )
