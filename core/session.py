"""The studio's session: the whole document as a value that reads and writes itself (Qt-free).

A session is the whole document as JSON::

    {"weft_session": 1, "method": "fast", "params": {"fast": {...}, ...}, "inputs": {"texture": "a.png"},
     "geometry": {"fast": {"region": [x, y, side]}, "nfpt": {"lines": {...}}}, "seed": 7}

``geometry`` holds each method's own geometry (its studio description's keys): a square ``[x, y, side]``,
feature lines ``{...}``, margins ``[left, top, right, bottom]``, and a mask as the name of its 1-bit PNG
written beside the session (relative to the session's folder), e.g. ``"mask": "s.weft.fill.mask.png"``.
A session's mask PNGs are written with it, by :meth:`Session.save` (or :meth:`Session.files` for a
caller that writes them elsewhere, e.g. on a worker with a lock of its own). Files written before
geometry was per method have one ``"prototype": [x, y, side]`` and one ``"lines": {...}`` instead;
each is given to every method with a geometry of that kind.
"""

from __future__ import annotations

import json
import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from . import registry
from .errors import WeftError
from .geometry import LINES, MARGINS, MASK, SQUARE, LineDraft, Margins, Mask, Square
from .jsonio import read_json_file
from .params import Params, relative_path
from .studio import Geometry

SESSION_VERSION = 1
LEGACY_SQUARE, LEGACY_LINES = "prototype", "lines"  # the version-1 keys of the one shared geometry


MAX_SEED = 2**31 - 1  # the studio's seed box


@dataclass(frozen=True)
class Session:
    """The studio's whole document as a value: it reads and writes itself, its masks included.

    Parameters
    ----------
    method : str
        The method shown.
    params : dict of str to Params
        The parameters of each method (a method not named has its defaults).
    inputs : dict of str to str
        Input name -> image file (absolute paths once read).
    geometry : dict of str to dict
        Method -> geometry key -> typed value (:class:`~weft.core.geometry.Square`,
        :class:`~weft.core.geometry.LineDraft`, :class:`~weft.core.geometry.Margins`,
        :class:`~weft.core.geometry.Mask`).
    seed : int
        The seed, 0..``MAX_SEED``.
    opened_for : dict of str to str, optional
        Input name -> the method it was opened for (``Studio.own_inputs``); None when the file did
        not record it.
    saved_as : str, optional
        The session file the studio saves to (a recovery file's; None otherwise).
    """

    method: str
    params: dict[str, Params] = field(default_factory=dict)
    inputs: dict[str, str] = field(default_factory=dict)
    geometry: dict[str, dict[str, Any]] = field(default_factory=dict)
    seed: int = 1
    opened_for: dict[str, str] | None = None
    saved_as: str | None = None

    @classmethod
    def read(cls, path: str | Path, *, dropped: list[str] | None = None) -> Session:
        """Parse and validate a session file (JSON only, at most ``weft.core.params.MAX_FILE_BYTES``),
        with its mask PNGs.

        Parameters
        ----------
        path : str or Path
            The session file; input paths come back absolute, relative ones resolved against its folder.
        dropped : list of str, optional
            With a list, a mask PNG that is missing or unreadable is left out of the geometry (the
            rest opens) and a one-line message naming it is appended to the list.

        Returns
        -------
        Session

        Raises
        ------
        WeftError
            One line naming the file if anything is wrong, so a bad file never half-replaces a document.
        """
        path = Path(path)
        data = read_json_file(path, "weft session")
        said: list[str] = []
        try:
            session = _session_from_data(data, path.resolve().parent, None if dropped is None else said)
        except WeftError as e:
            raise WeftError(f"{path}: {e}") from None
        if dropped is not None:
            dropped.extend(f"{path}: {line}" for line in said)
        return session

    def mask_files(self, path: str | Path) -> dict[Path, Mask]:
        """The mask PNGs a session at ``path`` keeps beside it.

        Parameters
        ----------
        path : str or Path
            The session file.

        Returns
        -------
        dict of Path to Mask
            File (:func:`mask_file`) -> mask, for each mask of each method.
        """
        return {
            mask_file(path, method, key): value
            for method, values in self.geometry.items()
            for key, value in values.items()
            if isinstance(value, Mask)
        }

    def to_data(self, path: str | Path | None = None, *, relative: bool = True) -> dict:
        """The session's JSON object.

        Parameters
        ----------
        path : str or Path, optional
            The file it goes to: each mask is named as its PNG beside it (:func:`mask_file`).
            Without it masks are left out (null) and file names are as held.
        relative : bool, default True
            File names relative to ``path``'s folder; False: absolute (a recovery file).

        Returns
        -------
        dict
            ``{"weft_session": 1, "method", "params", "inputs", "opened_for", "geometry", "seed"}``,
            and ``"saved_as"`` when set.
        """
        folder = None if path is None else Path(path).resolve().parent

        def name(p: str) -> str:
            if folder is None:
                return p
            return relative_path(p, folder) if relative else os.path.abspath(p)

        def geometry(method: str, key: str, value: Any) -> Any:
            if isinstance(value, Mask):
                return None if path is None else name(str(mask_file(path, method, key)))
            return value.to_json()

        data: dict[str, Any] = {
            "weft_session": SESSION_VERSION,
            "method": self.method,
            "params": {method: p.to_dict() for method, p in self.params.items()},
            "inputs": {key: name(p) for key, p in self.inputs.items()},
            "opened_for": dict(self.opened_for or {}),
            "geometry": {
                method: {key: geometry(method, key, value) for key, value in values.items()}
                for method, values in self.geometry.items()
                if values
            },
            "seed": self.seed,
        }
        if self.saved_as is not None:
            data["saved_as"] = os.path.abspath(self.saved_as)
        return data

    def files(self, path: str | Path, *, relative: bool = True) -> dict[Path, bytes]:
        """What :meth:`save` writes for a session at ``path``, encoded (the slow part: a large mask's PNG).

        Parameters
        ----------
        path : str or Path
            The session file.
        relative : bool, default True
            As :meth:`to_data`.

        Returns
        -------
        dict of Path to bytes
            Its masks' 1-bit PNGs, then the JSON last (in writing order: what names a file comes after it).
        """
        path = Path(path)
        out = {file: mask.to_png() for file, mask in self.mask_files(path).items()}
        out[path] = (json.dumps(self.to_data(path, relative=relative), indent=1) + "\n").encode("utf-8")
        return out

    def save(self, path: str | Path, *, relative: bool = True) -> None:
        """Write the session at ``path``: its masks as 1-bit PNGs beside it, then the JSON, each file
        atomically (on any thread: the value is immutable).

        Parameters
        ----------
        path : str or Path
            The session file.
        relative : bool, default True
            As :meth:`to_data`.

        Raises
        ------
        WeftError
            Naming the first file not written.
        """
        write_files(self.files(path, relative=relative))


def write_files(files: Mapping[Path, bytes]) -> None:
    """Write each file of ``files`` atomically, in order (masks before what names them).

    Parameters
    ----------
    files : mapping of Path to bytes
        File -> its bytes.

    Raises
    ------
    WeftError
        ``{file}: cannot write (reason)`` for the first file not written.
    """
    from .image import atomic_write_bytes

    for file, data in files.items():
        atomic_write_bytes(Path(file), data)


def write_masks(masks: Mapping[Path, Mask]) -> None:
    """Write each mask of ``masks`` as a 1-bit PNG, atomically (an export's masks beside it).

    Parameters
    ----------
    masks : mapping of Path to Mask
        File -> mask.

    Raises
    ------
    WeftError
        ``{file}: cannot write (reason)`` for the first file not written.
    """
    write_files({file: mask.to_png() for file, mask in masks.items()})


def read_session(path: str | Path, *, dropped: list[str] | None = None) -> Session:
    """Read a session file: :meth:`Session.read` (the same parameters, the same value returned)."""
    return Session.read(path, dropped=dropped)


def _session_from_data(data: Any, base: Path, dropped: list[str] | None = None) -> Session:
    if not isinstance(data, dict) or data.get("weft_session") != SESSION_VERSION:
        raise WeftError(f"not a weft session file (version {SESSION_VERSION})")
    methods = registry.methods()
    if data.get("method") not in methods:
        raise WeftError(f"unknown method {data.get('method')!r}")
    raw_params = _get(data, "params", dict, "an object of method name -> parameters", {})
    params = {}
    for name, values in raw_params.items():
        if name in methods:  # a method this version lacks is skipped, not fatal
            try:
                params[name] = methods[name].params.from_dict(values)
            except WeftError as e:
                raise WeftError(f"{name}: {e}") from None
    known_inputs = {i.name for m in methods.values() for i in m.inputs}
    inputs = {}
    for name, value in _get(data, "inputs", dict, "an object of input name -> image file", {}).items():
        if name not in known_inputs:
            raise WeftError(f"unknown input {name!r} (known: {', '.join(sorted(known_inputs))})")
        if not isinstance(value, str) or not value or "\0" in value:
            raise WeftError(f"input {name!r} = {value!r} is not a file path")
        inputs[name] = value if os.path.isabs(value) else str(base / value)
    proto = data.get(LEGACY_SQUARE)
    if proto is not None:
        try:
            proto = Square.from_json(proto, LEGACY_SQUARE)
        except WeftError:
            raise WeftError(f"{LEGACY_SQUARE} = {proto!r} must be [x, y, side] in pixels, or null") from None
    lines = LineDraft.from_json(
        _get(data, LEGACY_LINES, dict, "an object {image_lines, frontal_lines, frontal_size}", {}), LEGACY_LINES
    )
    seed = data.get("seed", 1)
    if not _ints([seed], 0, MAX_SEED):
        raise WeftError(f"seed = {seed!r} must be an integer in 0..{MAX_SEED}")
    # Geometry per method. Sessions written before it was per method have one "prototype" and one
    # "lines" for all: each goes to every method with a geometry of that kind.
    geometry: dict[str, dict[str, Any]] = {}
    for name, method in methods.items():
        if method.studio is None:
            continue
        for g in method.studio.geometry:
            if g.kind == SQUARE and proto is not None:
                geometry.setdefault(name, {})[g.key] = proto
            elif g.kind == LINES and (lines.image_lines or lines.frontal_lines):
                geometry.setdefault(name, {})[g.key] = lines
    for name, values in _get(data, "geometry", dict, "an object of method name -> geometry", {}).items():
        found = methods.get(name)
        if found is None or found.studio is None:
            continue  # a method this version lacks is skipped, as its parameters are
        if not isinstance(values, dict):
            raise WeftError(f"geometry of {name} must be an object of geometry name -> value")
        known = {g.key: g for g in found.studio.geometry}
        geometry[name] = {}
        for key, value in values.items():
            spec = known.get(key)
            if spec is None:
                raise WeftError(f"{name}: unknown geometry {key!r} (known: {', '.join(known) or 'none'})")
            try:
                geometry[name][key] = _geometry_from_json(spec, value, base)
            except _UnreadableMask as e:
                if dropped is None:
                    raise WeftError(f"{name}: {e}") from None
                dropped.append(f"{name}: {e}; dropped")
            except WeftError as e:
                raise WeftError(f"{name}: {e}") from None
    opened_for = _get(data, "opened_for", dict, "an object of input name -> method name", None)
    if opened_for is not None:
        opened_for = {k: v for k, v in opened_for.items() if k in inputs and isinstance(v, str)}
    saved_as = data.get("saved_as")
    return Session(
        method=data["method"],
        params=params,
        inputs=inputs,
        geometry=geometry,
        seed=seed,
        opened_for=opened_for,
        saved_as=saved_as if isinstance(saved_as, str) and saved_as else None,
    )


class _UnreadableMask(WeftError):
    """A session's mask PNG is missing or cannot be read (``read_session(dropped=...)`` drops it)."""


def mask_file(session: str | Path, method: str, key: str) -> Path:
    """Where a session at ``session`` keeps the mask ``key`` of ``method``: a 1-bit PNG beside it
    (``s.weft.json`` -> ``s.weft.fill.mask.png``)."""
    session = Path(session)
    stem = session.name[:-5] if session.name.lower().endswith(".json") else session.name
    return session.with_name(f"{stem}.{method}.{key}.png")


def _geometry_from_json(g: Geometry, value: Any, base: Path):
    if value is None:
        return None
    if g.kind == MASK:
        if not isinstance(value, str) or not value or "\0" in value:
            raise WeftError(f"{g.key} = {value!r} must be the name of a mask PNG beside the session")
        path = Path(value) if os.path.isabs(value) else base / value
        try:
            return Mask.read(path, g.key)
        except WeftError as e:
            raise _UnreadableMask(str(e)) from None
    if g.kind == MARGINS:
        return Margins.from_json(value, g.key)
    if g.kind == SQUARE:
        try:
            return Square.from_json(value, g.key)
        except WeftError:
            raise WeftError(f"{g.key} = {value!r} must be [x, y, side] in pixels, or null") from None
    return LineDraft.from_json(value, g.key)


def _get(data: dict, key: str, kind: type, what: str, default):
    value = data.get(key)
    if value is None:
        return default
    if not isinstance(value, kind):
        raise WeftError(f"{key} must be {what}")
    return value


def _ints(values, lo: int, hi: int | None = None) -> bool:
    return all(isinstance(v, int) and not isinstance(v, bool) and lo <= v and (hi is None or v <= hi) for v in values)
