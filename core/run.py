"""One item: a method run on image files, and the recipe its output carries.

``weft METHOD``, ``weft run`` and every item of a batch (:mod:`weft.core.batch`) go through these same
functions, so a batch output is byte for byte what ``weft run`` gives for that item's recipe:

* :func:`load_recipe` reads a recipe (``.json``, or a PNG exported by weft) and
  :func:`check_recipe` validates it against its method (inputs it takes, parameters; geometry that
  names a file, as older recipes' ``"lines": "L.json"``, is read there, relative to the recipe);
* :func:`output_recipe` is the recipe an output at a given path carries (paths relative to its folder);
* :func:`render` loads the inputs, checks their sizes, runs the method and names the file behind an
  error about one input; the caller encodes or saves the result with the recipe
  (:func:`weft.core.image.save_image` / :func:`weft.core.image.encode_image`).
"""

from __future__ import annotations

import contextlib
import os
import time
from collections.abc import Mapping
from pathlib import Path

from .errors import ImageError, WeftError
from .geometry import Square
from .params import Params, Recipe, relative_path
from .readfile import kind_of, open_regular, shown


def load_recipe(path: str) -> Recipe:
    """A recipe from a ``.json`` file or from the ``weft-recipe`` chunk of a PNG weft exported.

    Parameters
    ----------
    path : str
        The file.

    Returns
    -------
    Recipe
        With its relative input paths resolved against the file's folder.

    Raises
    ------
    WeftError
        One line naming the file; an image of another format is told that only PNG exports (and
        ``.json`` files) carry a recipe.
    """
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
    """Validate ``recipe`` against its method before any image is read.

    Messages do not name the recipe file; the caller puts it in front.

    Parameters
    ----------
    recipe : Recipe
        The recipe.
    base : pathlib.Path
        The recipe file's folder: a geometry that names a file is read relative to it, never to the
        current folder.
    supplied : tuple of str, optional
        Inputs given from elsewhere (a batch's ``--over``): they need not be in the recipe, nor exist.

    Returns
    -------
    dict
        Its parameters in their JSON form with every geometry inline.

    Raises
    ------
    WeftError
        A bad parameter, a missing input, an input that is not an image file.
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
    """The recipe a run's output at ``out`` carries.

    Input paths are relative to the output's folder (``weft run OUT.png`` then finds them wherever
    the folder moves); geometry (feature lines, a view) is inline, so it needs no other file.

    Parameters
    ----------
    method : Method
        The method run.
    params : Params
        Its parameters.
    input_paths : mapping of str to str
        Input name -> file.
    seed : int
        The seed used.
    region : (int, int, int) or None
        The square of the first input the method ran on.
    out : str or os.PathLike
        The output file.

    Returns
    -------
    Recipe
    """
    out_dir = Path(out).resolve().parent
    rel_inputs = {name: relative_path(path, out_dir) for name, path in input_paths.items()}
    return Recipe(
        method=method.name,
        params=params.to_dict(),
        inputs=rel_inputs,
        seed=seed,
        region=None if region is None else Square(*region),
    )


def render(
    method,
    params: Params,
    input_paths: Mapping[str, str],
    seed: int,
    region: tuple[int, int, int] | None = None,
    *,
    progress=None,
    cancel=None,
    warm_up: bool = True,
    shown_paths: Mapping[str, str] | None = None,
    infos: dict | None = None,
):
    """Load the inputs, run ``method`` and time it.

    The first input is cropped to ``region`` when given; an input smaller than its ``min_side`` is
    refused naming its file; a ``WeftError`` about one input gets its file name in front. An input
    whose ``InputSpec.alpha`` is set keeps its alpha channel.

    Parameters
    ----------
    method : Method
        The method.
    params : Params
        Its validated parameters.
    input_paths : mapping of str to str
        Input name -> image file.
    seed : int
        The seed.
    region : (int, int, int), optional
        ``(x, y, side)`` of the first input to run on.
    progress, cancel
        Progress callback; cancel token.
    warm_up : bool, default True
        Load the method's kernels first (when the method asks for that on the command line), so
        ``seconds`` is the compute alone; a kernel compiled during the run (this thread's numba
        compiles) is left out of it too.
    shown_paths : mapping of str to str, optional
        The names to use in messages when the files read are copies (a batch's shipped inputs).
    infos : dict, optional
        Receives each input's :class:`~weft.core.image.ImageInfo`.

    Returns
    -------
    result : Result
    seconds : float
        The compute time.

    Raises
    ------
    WeftError
        A bad input or a parameter the inputs do not suit; one line naming the file when it is about one.
    """
    from .image import load_image

    shown = dict(shown_paths or input_paths)
    if region is not None and not method.takes_region:
        raise WeftError(
            f"weft {method.name} takes no --region (it works on the whole {method.inputs[0].name}; "
            f"crop the image first)"
        )
    keep_alpha = {spec.name for spec in method.inputs if spec.alpha}
    loaded = {name: load_image(path, alpha=name in keep_alpha) for name, path in input_paths.items()}
    images = {name: item.image for name, item in loaded.items()}
    if infos is not None:
        infos.update({name: item.info for name, item in loaded.items()})
    if region is not None:
        first = method.inputs[0].name
        images[first] = Square(*region).crop(images[first], what=first)
    for spec in method.inputs:
        if spec.name in images and min(images[spec.name].shape[:2]) < spec.min_side:
            h, w = images[spec.name].shape[:2]
            cropped = " (the --region crop)" if region is not None and spec is method.inputs[0] else ""
            raise ImageError(
                f"{shown[spec.name]}: the {spec.name} is {w}x{h}{cropped}; weft {method.name} "
                f"needs at least {spec.min_side}x{spec.min_side} pixels",
                path=shown[spec.name],
            )
    from . import registry

    with registry.watch_compiles(this_thread=True) as compiles:
        if warm_up and method.warm_up_in_cli:
            registry.warm_up(method.name)  # load compiled kernels now, so "seconds" is the compute alone
        before = compiles.seconds
        t0 = time.perf_counter()
        try:
            result = method.run(images, params, rng=seed, progress=progress, cancel=cancel)
        except WeftError as e:
            if e.input in shown:  # about one image (a block that does not fit it): say which file
                named = type(e)(f"{shown[e.input]}: {e}")
                named.__dict__.update(e.__dict__)
                raise named from None
            raise
        # kernels compiled on the way (a first run of a method that loads them lazily) are not compute
        seconds = time.perf_counter() - t0 - (compiles.seconds - before)
    return result, max(0.0, seconds)
