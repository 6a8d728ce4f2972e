"""The recipe that records a run: method, parameters, inputs, seed (and the source square and bit
depth when chosen), read and written as JSON; a weft PNG carries one (:func:`weft.core.image.read_recipe`)."""

from __future__ import annotations

import json
import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .errors import InvalidParameter, WeftError
from .geometry import Square
from .jsonio import parse_json, read_json_file

RECIPE_VERSION = 1


@dataclass(frozen=True)
class Recipe:
    """Everything needed to reproduce a result: method, parameters, input paths and seed.

    JSON form (DESIGN.md)::

        {"weft": 1, "method": "fast", "params": {...},
         "inputs": {"texture": "a.png", "target": "b.png"}, "seed": 7}

    plus, when the user picked one, ``"region": [x, y, side]``: the square of the texture the method
    used as its source (the studio's prototype rectangle; ``--region X,Y,S`` on the command line);
    and, when it was chosen (a studio export, ``--bit-depth``), ``"bit_depth": 8`` or ``16``: the bits
    per sample of the output, which ``weft run`` then writes (without it: 8, or the depth of the input
    the method keeps, ``Method.depth_from``).

    Input paths are stored as given; :meth:`load` resolves relative paths against the folder of the
    recipe file, so a recipe next to its images keeps working when the folder moves.
    """

    method: str
    params: Mapping[str, Any] = field(default_factory=dict)
    inputs: Mapping[str, str] = field(default_factory=dict)
    seed: int | None = None
    region: Square | None = None
    bit_depth: int | None = None

    def to_json(self, relative_to: str | os.PathLike | None = None) -> str:
        """The recipe's JSON text; with ``relative_to`` (the folder of the file that will carry it),
        input paths are written relative to it."""
        inputs = dict(self.inputs)
        if relative_to is not None:
            inputs = {k: relative_path(v, relative_to) if os.path.isabs(v) else v for k, v in inputs.items()}
        data = {
            "weft": RECIPE_VERSION,
            "method": self.method,
            "params": dict(self.params),
            "inputs": inputs,
            "seed": self.seed,
        }
        if self.region is not None:
            data["region"] = Square(*self.region).to_json()
        if self.bit_depth is not None:
            data["bit_depth"] = self.bit_depth
        return json.dumps(data, sort_keys=False)

    @classmethod
    def from_json(cls, text: str, *, base: str | os.PathLike | None = None) -> Recipe:
        try:
            data = parse_json(text)
        except WeftError as e:
            raise WeftError(f"recipe is {e}") from None
        return cls.from_data(data, base=base)

    @classmethod
    def from_data(cls, data: Any, *, base: str | os.PathLike | None = None) -> Recipe:
        """Validate a parsed recipe; relative input paths are joined to ``base`` when given."""
        if not isinstance(data, dict):
            raise WeftError("recipe must be a JSON object")
        version = data.get("weft")
        if version != RECIPE_VERSION:
            raise WeftError(
                f'recipe has "weft": {version!r}; this version of weft reads recipes of version {RECIPE_VERSION}'
            )
        method = data.get("method")
        if not isinstance(method, str):
            raise WeftError('recipe has no "method" (a string such as "quilt")')
        params = data.get("params", {})
        inputs = data.get("inputs", {})
        seed = data.get("seed")
        if not isinstance(params, dict):
            raise WeftError('recipe "params" must be a JSON object')
        if not isinstance(inputs, dict) or not all(isinstance(v, str) for v in inputs.values()):
            raise WeftError('recipe "inputs" must map input names to file paths')
        for name, value in inputs.items():
            if not value or "\0" in value:
                raise WeftError(f"recipe input {name!r} = {value!r} is not a file path")
        if seed is not None and (isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed < 2**63):
            raise WeftError(f'recipe "seed" = {seed!r} must be a non-negative integer below 2**63, or null')
        region = data.get("region")
        if region is not None:
            try:
                region = Square.from_json(region, "region")
            except InvalidParameter:
                raise WeftError(f'recipe "region" = {region!r} must be [x, y, side] in pixels') from None
        bit_depth = data.get("bit_depth")
        if bit_depth is not None and (isinstance(bit_depth, bool) or bit_depth not in (8, 16)):
            raise WeftError(f'recipe "bit_depth" = {bit_depth!r} must be 8 or 16')
        if base is not None:
            inputs = {k: str(Path(base) / v) if not os.path.isabs(v) else v for k, v in inputs.items()}
        return cls(method=method, params=params, inputs=inputs, seed=seed, region=region, bit_depth=bit_depth)

    @classmethod
    def load(cls, path: str | os.PathLike) -> Recipe:
        """Read a recipe JSON file (at most :data:`MAX_FILE_BYTES`); messages start with its name."""
        path = Path(path)
        data = read_json_file(path, "recipe")
        try:
            return cls.from_data(data, base=path.resolve().parent)
        except WeftError as e:
            raise WeftError(f"{path}: {e}") from None

    def save(self, path: str | os.PathLike) -> None:
        """Write the recipe to ``path`` (atomically), input paths relative to its folder."""
        from .image import atomic_write_bytes

        path = Path(path)
        atomic_write_bytes(path, (self.to_json(relative_to=path.resolve().parent) + "\n").encode("utf-8"))


def relative_path(path: str, folder: str | os.PathLike) -> str:
    """``path`` relative to ``folder``, as recipes and sessions store paths relative to their own file.

    Parameters
    ----------
    path : str
        An absolute path.
    folder : str or os.PathLike
        The folder of the file that will carry the path.

    Returns
    -------
    str
        The relative path, or ``path`` itself when there is no relative form (another drive on Windows).
    """
    try:
        return os.path.relpath(Path(path).resolve(), Path(folder).resolve())
    except ValueError:
        return str(Path(path).resolve())
