"""The studio's session files: reading and validating them (Qt-free; the studio writes them).

A session is the whole document as JSON::

    {"weft_session": 1, "method": "fast", "params": {"fast": {...}, ...}, "inputs": {"texture": "a.png"},
     "geometry": {"fast": {"region": [x, y, side]}, "nfpt": {"lines": {...}}}, "seed": 7}

``geometry`` holds each method's own geometry (its studio description's keys): a square ``[x, y, side]``,
feature lines ``{...}``, margins ``[left, top, right, bottom]``, and a mask as the name of its 1-bit PNG
written beside the session (relative to the session's folder), e.g. ``"mask": "s.weft.fill.mask.png"``.
Files of the older format, without per-method geometry, have one ``"prototype": [x, y, side]`` and
one ``"lines": {...}`` instead; each is given to every method with a geometry of that kind.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from . import registry
from .errors import WeftError
from .geometry import LINES, MARGINS, MASK, SQUARE, LineDraft, Margins, Mask, Square
from .jsonio import read_json_file
from .studio import Geometry

SESSION_VERSION = 1
LEGACY_SQUARE, LEGACY_LINES = "prototype", "lines"  # the version-1 keys of the one shared geometry


MAX_SEED = 2**31 - 1  # the studio's seed box


def read_session(path: str | Path, *, dropped: list[str] | None = None) -> dict:
    """Parse and validate a session file (JSON only, at most ``weft.core.jsonio.MAX_FILE_BYTES``).

    A bad file never half-replaces a document: anything wrong is one error.

    Parameters
    ----------
    path : str or pathlib.Path
        The session file.
    dropped : list of str, optional
        With a list, a mask PNG that is missing or unreadable is left out of the geometry instead (the
        rest opens) and a one-line message naming it is appended to the list.

    Returns
    -------
    dict
        ``method``, ``params`` (per method), ``inputs`` (absolute paths, relative ones resolved
        against the session's folder), ``geometry`` (typed values per method), ``seed`` and
        ``opened_for``.

    Raises
    ------
    WeftError
        One line naming the file and what is wrong with it.
    """
    path = Path(path)
    data = read_json_file(path, "weft session")
    said: list[str] | None = None if dropped is None else []
    try:
        session = _session_from_data(data, path.resolve().parent, said)
    except WeftError as e:
        raise WeftError(f"{path}: {e}") from None
    if dropped is not None and said is not None:
        dropped.extend(f"{path}: {line}" for line in said)
    return session


def _session_from_data(data: Any, base: Path, dropped: list[str] | None = None) -> dict:
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
    # Geometry per method. Sessions of the older format have one "prototype" and one "lines" for
    # all: each goes to every method with a geometry of that kind.
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
        owner = methods.get(name)
        if owner is None or owner.studio is None:
            continue  # a method this version lacks is skipped, as its parameters are
        if not isinstance(values, dict):
            raise WeftError(f"geometry of {name} must be an object of geometry name -> value")
        known = {g.key: g for g in owner.studio.geometry}
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
    return {
        "method": data["method"],
        "params": params,
        "inputs": inputs,
        "geometry": geometry,
        "seed": seed,
        "opened_for": opened_for,
    }


class _UnreadableMask(WeftError):
    """A session's mask PNG is missing or cannot be read (``read_session(dropped=...)`` drops it)."""


def mask_file(session: str | Path, method: str, key: str) -> Path:
    """Where a session keeps a painted mask: a 1-bit PNG beside it.

    Parameters
    ----------
    session : str or pathlib.Path
        The session file (``s.weft.json``).
    method, key : str
        The method and its mask geometry's key.

    Returns
    -------
    pathlib.Path
        E.g. ``s.weft.fill.mask.png``.
    """
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
