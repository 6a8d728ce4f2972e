"""One item: a method run on image files, and the recipe its output carries.

``weft METHOD``, ``weft run`` and every item of a batch (:mod:`core.batch`) go through these same
functions, so a batch output is byte for byte what ``weft run`` gives for that item's recipe:

* :func:`load_recipe` reads a recipe (``.json``, or a PNG exported by weft) and
  :func:`check_recipe` validates it against its method (inputs it takes, parameters, files);
* :func:`output_recipe` is the recipe an output at a given path carries (paths relative to its folder);
* :func:`render` loads the inputs, checks their sizes, runs the method and names the file behind an
  error about one input; the caller encodes or saves the result with the recipe
  (:func:`core.image.save_image` / :func:`core.image.encode_image`).
"""

from __future__ import annotations

import os
import time
from pathlib import Path
from typing import Mapping

from .errors import ImageError, WeftError
from .params import Params, Recipe, specs


def names_file(value) -> bool:
    """Whether a text parameter names an existing file (JSON given inline, e.g. ``{...}``, does not)."""
    if not isinstance(value, str) or not value or value.lstrip().startswith(("{", "[")):
        return False
    try:
        return Path(value).is_file()
    except (OSError, ValueError):  # too long for a file name, or a NUL in it
        return False


def relative_to(path: str, folder: Path) -> str:
    """``path`` relative to ``folder`` (recipes store paths relative to the file that carries them)."""
    try:
        return os.path.relpath(Path(path).resolve(), folder)
    except ValueError:  # another drive on Windows
        return str(Path(path).resolve())


def resolve_file_params(method, params: dict, base: Path) -> dict:
    """Text parameters of a recipe that name files (nfpt's lines, view), made absolute against the
    recipe's folder ``base``, never the current directory; a ``.json`` one that is not there is an error
    naming the parameter and the file."""
    out = dict(params)
    for spec in specs(method.params):
        value = out.get(spec.name)
        if spec.kind != "str" or not isinstance(value, str) or not value or value.lstrip().startswith(("{", "[")):
            continue  # not text, or JSON given inline
        path = value if os.path.isabs(value) else str(base / value)
        if names_file(path):
            out[spec.name] = path
        elif Path(value).suffix.lower() == ".json" and not os.path.exists(path):
            raise WeftError(f"parameter '{spec.name}' names {value}, but {path} does not exist")
    return out


def load_recipe(path: str) -> Recipe:
    """A recipe from a ``.json`` file or from the ``weft-recipe`` chunk of a PNG weft exported; its
    relative input paths are resolved against the file's folder. One-line ``WeftError`` naming the file."""
    from .image import read_recipe

    p = Path(path)
    if not p.exists():
        raise WeftError(f"{path}: no such file")
    if p.suffix.lower() == ".png":
        text = read_recipe(p)
        if text is None:
            raise WeftError(f"{path}: this PNG carries no weft recipe")
        try:
            return Recipe.from_json(text, base=p.resolve().parent)
        except WeftError as e:
            raise WeftError(f"{path}: {e}") from None
    return Recipe.load(p)


def check_recipe(recipe: Recipe, base: Path, *, supplied: tuple[str, ...] = ()) -> dict:
    """Validate ``recipe`` against its method before any image is read; returns its parameters with
    file parameters made absolute against ``base`` (the recipe file's folder).

    ``supplied`` names inputs given from elsewhere (a batch's ``--over``): they need not be in the
    recipe, nor exist. Messages do not name the recipe file; the caller puts it in front.
    """
    from . import registry

    method = registry.get(recipe.method)
    takes = [i.name for i in method.inputs]
    unknown = sorted(set(recipe.inputs) - set(takes))
    if unknown:
        raise WeftError(f"recipe names input {', '.join(map(repr, unknown))}, which {method.name} does not "
                        f"take (it takes {', '.join(takes)})")
    missing = [i.name for i in method.inputs if i.required and i.name not in recipe.inputs and i.name not in supplied]
    if missing:
        raise WeftError(f"recipe names no {', '.join(missing)} image for {method.name}")
    method.params.from_dict(recipe.params)
    for name, path in recipe.inputs.items():
        if name not in supplied and not os.path.exists(path):
            raise WeftError(f"the {name} image {path} does not exist")
    return resolve_file_params(method, dict(recipe.params), base)


def output_recipe(method, params: Params, input_paths: Mapping[str, str], seed: int,
                  region: tuple[int, int, int] | None, out: str | os.PathLike) -> Recipe:
    """The recipe a run's output at ``out`` carries: input paths and file parameters relative to the
    output's folder (``weft run OUT.png`` then finds them wherever the folder moves)."""
    out_dir = Path(out).resolve().parent
    rel_inputs = {name: relative_to(path, out_dir) for name, path in input_paths.items()}
    recipe_params = params.to_dict()
    for spec in specs(method.params):  # text parameters naming files (nfpt's --lines, --view)
        value = recipe_params.get(spec.name)
        if spec.kind == "str" and names_file(value):
            recipe_params[spec.name] = relative_to(value, out_dir)
    return Recipe(method=method.name, params=recipe_params, inputs=rel_inputs, seed=seed, region=region)


def render(method, params: Params, input_paths: Mapping[str, str], seed: int,
           region: tuple[int, int, int] | None = None, *, progress=None, cancel=None, warm_up: bool = True,
           shown_paths: Mapping[str, str] | None = None):
    """Load the inputs, run ``method`` and return ``(Result, seconds)`` (compute time only).

    The first input is cropped to ``region`` when given; an input smaller than its ``min_side`` is
    refused naming its file; a ``WeftError`` about one input gets its file name in front.
    ``warm_up`` loads the method's kernels first (when the method asks for that on the command line),
    so ``seconds`` is the compute alone; a kernel compiled during the run (this thread's numba
    compiles) is left out of it too. ``shown_paths`` are the names to use in messages when the
    files read are copies (a batch's shipped inputs).
    """
    from .image import crop_square, load_image

    shown = dict(shown_paths or input_paths)
    images = {name: load_image(path).image for name, path in input_paths.items()}
    if region is not None:
        first = method.inputs[0].name
        images[first] = crop_square(images[first], region, what=first)
    for spec in method.inputs:
        if spec.name in images and min(images[spec.name].shape[:2]) < spec.min_side:
            h, w = images[spec.name].shape[:2]
            cropped = " (the --region crop)" if region is not None and spec is method.inputs[0] else ""
            raise ImageError(f"{shown[spec.name]}: the {spec.name} is {w}x{h}{cropped}; weft {method.name} "
                             f"needs at least {spec.min_side}x{spec.min_side} pixels", path=shown[spec.name])
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
