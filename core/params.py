"""Frozen, validated parameter dataclasses (the recipe that records a run is :mod:`weft.core.recipe`).

One source of truth for every method's parameters: a method declares its parameters once with
:func:`param`, the dataclass validates itself when built, and the CLI (options) and the GUI
(sliders, tooltips, reset to default) read the same :class:`Spec` objects through :func:`specs`.

Example
-------
>>> from dataclasses import dataclass
>>> @dataclass(frozen=True)
... class DemoParams(Params):
...     block: int = param(32, lo=2, hi=512, symbol="B", help="block side in pixels")
...     overlap: int = param(6, lo=1, hi=256, help="overlap between blocks")
...     def check(self):
...         if self.overlap >= self.block:
...             raise out_of_range("overlap", self.overlap, 1, self.block - 1,
...                                f"must be smaller than block = {self.block}")
>>> DemoParams(block=32, overlap=40)
Traceback (most recent call last):
...
weft.core.errors.InvalidParameter: parameter 'overlap' = 40 is outside 1..31 (must be smaller than block = 32)

Rules: a value of the wrong type or outside its range raises :class:`~weft.core.errors.InvalidParameter`
naming the parameter, the value and the allowed range. Nothing is clamped silently. Integral
numpy scalars are accepted for ``int`` parameters and stored as ``int``; ``bool`` is never an ``int``.
"""

from __future__ import annotations

import dataclasses
import math
import numbers
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, Self

import numpy as np

from .errors import InvalidParameter
from .geometry import MAX_SIDE, GeometryValue, whole_number
from .jsonio import MAX_FILE_BYTES, parse_json, read_json_file  # noqa: F401 (re-exported)
from .recipe import RECIPE_VERSION, Recipe, relative_path  # noqa: F401 (re-exported: callers import them from here)

# The public names, those of weft.core.recipe included (documented here).
__all__ = [
    "Spec",
    "out_of_range",
    "parse_size",
    "param",
    "Params",
    "specs",
    "as_rng",
    "Recipe",
    "relative_path",
]

KINDS = ("int", "float", "bool", "choice", "size", "str", "geometry")
INT, FLOAT, BOOL, CHOICE, SIZE, STR, GEOMETRY = KINDS  # for front ends that branch on the kind


@dataclass(frozen=True)
class Spec:
    """What a front end needs to know about one parameter.

    Attributes
    ----------
    name : parameter name (the dataclass field); the CLI option is ``--name`` with ``_`` -> ``-``.
    kind : one of ``int, float, bool, choice, size, str, geometry``; ``size`` is a ``(width, height)``
        pair; ``geometry`` a typed value of class ``type`` (:mod:`weft.core.geometry`: a square, feature
        lines, a view), parsed at the edges by the type's ``parse`` (command line), ``from_json``
        (recipes, sessions) and ``coerce`` (Python callers), written by its ``to_json``.
    default : the default value (from the paper where it gives one).
    lo, hi : inclusive bounds for ``int``, ``float`` and each side of ``size``.
    choices : the allowed values of a ``choice``.
    optional : ``None`` is allowed (meaning "derived from the inputs", see the method's docs).
    symbol : the paper's symbol (shown in tooltips), e.g. ``"p_l"`` or ``"α"``.
    help : one sentence for tooltips and ``--help``.
    step : slider step for ``float`` parameters; for an ``int``, the values lie on ``lo + k * step``
        (2 for a side that must be odd from 3, or even from 8): sliders and grids keep to them.
    type : the class of a ``geometry`` parameter (a :class:`~weft.core.geometry.GeometryValue`).
    """

    name: str
    kind: str
    default: Any
    lo: float | None = None
    hi: float | None = None
    choices: tuple = ()
    optional: bool = False
    symbol: str = ""
    help: str = ""
    step: float | None = None
    type: type[GeometryValue] | None = None

    @property
    def option(self) -> str:
        return "--" + self.name.replace("_", "-")

    def on_grid(self, value: float, lo: float | None = None, hi: float | None = None, up: bool | None = None) -> int:
        """The value of an ``int`` parameter with a ``step`` nearest to ``value`` on its grid
        ``lo + k * step`` (the Spec's ``lo``), within ``lo``..``hi`` (the Spec's range unless given).

        Parameters
        ----------
        value : float
            A value from a slider or a range.
        lo, hi : float, optional
            A narrower range to stay in (the range the open inputs allow).
        up : bool, optional
            Round up (True) or down (False) when ``value`` is off the grid: the way a slider moved;
            None rounds to the nearer.

        Returns
        -------
        int
            ``value`` itself when the parameter has no step or it is on the grid.
        """
        v = int(round(value))
        step = int(self.step or 1)
        if self.kind != "int" or step <= 1:
            return v
        base = int(self.lo or 0)
        k = (v - base) / step
        k = math.ceil(k) if up else math.floor(k) if up is False else math.floor(k + 0.5)
        out = base + int(k) * step
        low = self.lo if lo is None else lo
        high = self.hi if hi is None else hi
        while high is not None and out > high:
            out -= step
        while low is not None and out < low:
            out += step
        return out

    def range_text(self) -> str:
        if self.kind == "choice":
            return ", ".join(str(c) for c in self.choices)
        if self.lo is not None and self.hi is not None:
            return f"{_fmt(self.lo)}..{_fmt(self.hi)}"
        return ""

    def validate(self, value: Any) -> Any:
        """Return ``value`` converted to the canonical type, or raise ``InvalidParameter``."""
        name = self.name
        if value is None:
            if self.optional:
                return None
            raise InvalidParameter(f"parameter '{name}' is required", name=name, value=value)
        if self.kind == "int":
            if isinstance(value, bool) or not isinstance(value, numbers.Integral):
                raise InvalidParameter(f"parameter '{name}' = {value!r} must be an integer", name=name, value=value)
            value = int(value)
            self._check_bounds(value)
        elif self.kind == "float":
            if isinstance(value, bool) or not isinstance(value, numbers.Real):
                raise InvalidParameter(f"parameter '{name}' = {value!r} must be a number", name=name, value=value)
            value = float(value)
            if not math.isfinite(value):
                raise InvalidParameter(f"parameter '{name}' = {value} must be a finite number", name=name, value=value)
            self._check_bounds(value)
        elif self.kind == "bool":
            if not isinstance(value, (bool, np.bool_)):
                raise InvalidParameter(f"parameter '{name}' = {value!r} must be true or false", name=name, value=value)
            value = bool(value)
        elif self.kind == "choice":
            if value not in self.choices:
                raise InvalidParameter(
                    f"parameter '{name}' = {value!r} is not one of {self.range_text()}", name=name, value=value
                )
        elif self.kind == "size":
            if isinstance(value, str):
                value = parse_size(value, name)
            if (
                not isinstance(value, (tuple, list))
                or len(value) != 2
                or any(isinstance(v, bool) or not isinstance(v, numbers.Integral) for v in value)
            ):
                raise InvalidParameter(
                    f"parameter '{name}' = {value!r} must be a size WIDTHxHEIGHT in pixels", name=name, value=value
                )
            value = (int(value[0]), int(value[1]))
            lo = int(self.lo if self.lo is not None else 1)
            hi = int(self.hi if self.hi is not None else MAX_SIDE)
            if not all(lo <= v <= hi for v in value):
                raise InvalidParameter(
                    f"parameter '{name}' = {value[0]}x{value[1]} has a side outside {lo}..{hi}", name=name, value=value
                )
        elif self.kind == "geometry" and self.type is not None:  # (param() gives every geometry its type)
            value = self.type.coerce(value, name)
        elif self.kind == "str":
            if not isinstance(value, str):
                raise InvalidParameter(f"parameter '{name}' = {value!r} must be text", name=name, value=value)
        return value

    def _check_bounds(self, value: float) -> None:
        if (self.lo is not None and value < self.lo) or (self.hi is not None and value > self.hi):
            raise out_of_range(self.name, value, self.lo, self.hi)

    def parse(self, text: str) -> Any:
        """Parse a command-line string into a validated value."""
        if self.optional and text.lower() in ("none", "auto"):
            return None
        if self.kind == "int":
            try:
                value: Any = whole_number(text.strip())
            except ValueError:
                raise InvalidParameter(
                    f"parameter '{self.name}' = {text!r} must be an integer", name=self.name, value=text
                ) from None
        elif self.kind == "float":
            try:
                if not text.isascii() or "_" in text:  # float() also takes 1_0.5 and other scripts' digits
                    raise ValueError
                value = float(text)
            except ValueError:
                raise InvalidParameter(
                    f"parameter '{self.name}' = {text!r} must be a number", name=self.name, value=text
                ) from None
        elif self.kind == "bool":
            low = text.lower()
            if low not in ("1", "0", "true", "false", "yes", "no", "on", "off"):
                raise InvalidParameter(
                    f"parameter '{self.name}' = {text!r} must be true or false", name=self.name, value=text
                )
            value = low in ("1", "true", "yes", "on")
        elif self.kind == "size":
            value = parse_size(text, self.name)
        elif self.kind == "geometry" and self.type is not None:
            value = self.type.parse(text, self.name)
        else:
            value = text
        return self.validate(value)


def _fmt(x: float) -> str:
    return str(int(x)) if float(x).is_integer() else f"{x:g}"


def out_of_range(
    name: str, value: Any, lo: float | None, hi: float | None, why: str = "", input: str | None = None
) -> InvalidParameter:
    """Build the standard message: ``parameter 'overlap' = 40 is outside 1..31 (why)``.

    Parameters
    ----------
    name : str
        The parameter.
    value : object
        The value given.
    lo, hi : float or None
        The allowed range (None: unbounded on that side).
    why : str, optional
        Why the range is what it is, appended in parentheses.
    input : str, optional
        The method input whose size set the bound (see ``WeftError.input``).

    Returns
    -------
    InvalidParameter
        The error, for the caller to raise.
    """
    lo_t = "-inf" if lo is None else _fmt(lo)
    hi_t = "inf" if hi is None else _fmt(hi)
    shown = _fmt(value) if isinstance(value, (int, float)) else repr(value)
    msg = f"parameter '{name}' = {shown} is outside {lo_t}..{hi_t}"
    if why:
        msg += f" ({why})"
    error = InvalidParameter(msg, name=name, value=value)
    error.input = input
    return error


def parse_size(text: str, name: str = "size") -> tuple[int, int]:
    """Parse ``"512x384"`` (or ``"512"`` for a square) into ``(512, 384)``.

    Parameters
    ----------
    text : str
        ``WIDTHxHEIGHT`` or ``SIDE`` in whole pixels (``×`` is read as ``x``).
    name : str, default "size"
        The parameter, for the message.

    Returns
    -------
    (int, int)
        Width and height.

    Raises
    ------
    InvalidParameter
        The text is not one or two whole numbers joined by ``x``.
    """
    parts = text.lower().replace("×", "x").split("x")
    try:
        if len(parts) == 1:
            w = h = whole_number(parts[0].strip())
        elif len(parts) == 2:
            w, h = whole_number(parts[0].strip()), whole_number(parts[1].strip())
        else:
            raise ValueError
    except ValueError:
        raise InvalidParameter(
            f"parameter '{name}' = {text!r} must be a size WIDTHxHEIGHT, e.g. 512x512", name=name, value=text
        ) from None
    return w, h


def param(
    default: Any,
    *,
    lo: float | None = None,
    hi: float | None = None,
    choices: Sequence | None = None,
    kind: str | None = None,
    optional: bool = False,
    symbol: str = "",
    help: str = "",
    step: float | None = None,
    type: type[GeometryValue] | None = None,
) -> Any:
    """Declare a parameter field of a :class:`Params` dataclass.

    The kind is inferred from ``default`` (``choices`` given -> ``choice``; a 2-tuple -> ``size``)
    unless ``kind`` says otherwise.

    Parameters
    ----------
    default : object
        The default value (None with ``optional``: "auto", resolved by the method).
    lo, hi : float, optional
        The allowed range of a number or of a size's sides.
    choices : sequence, optional
        The allowed values of a ``choice``.
    kind : str, optional
        One of :data:`KINDS`; inferred from ``default`` when omitted.
    optional : bool, default False
        Whether None is allowed.
    symbol : str, optional
        The paper's symbol (``"B"``, ``"p_l"``), shown beside the slider.
    help : str, optional
        One line for the CLI's help, the slider's tooltip and the docs.
    step : float, optional
        The slider's step for a float; for an int, the values lie on ``lo + k * step``.
    type : type, optional
        The geometry type of a ``geometry`` parameter (and only of one).

    Returns
    -------
    dataclasses.Field
        The field, with its :class:`Spec` metadata.

    Raises
    ------
    TypeError
        The kind cannot be inferred or is unknown, or ``type`` and ``kind="geometry"`` do not go together.
    """
    if kind is None:
        if choices is not None:
            kind = "choice"
        elif isinstance(default, bool):
            kind = "bool"
        elif isinstance(default, int):
            kind = "int"
        elif isinstance(default, float):
            kind = "float"
        elif isinstance(default, tuple):
            kind = "size"
        elif isinstance(default, str):
            kind = "str"
        else:
            raise TypeError(f"cannot infer the kind of a parameter with default {default!r}")
    if kind not in KINDS:
        raise TypeError(f"unknown parameter kind {kind!r}")
    if (kind == "geometry") != (type is not None):
        raise TypeError("a geometry parameter needs its type (and only a geometry parameter has one)")
    if type is not None and not issubclass(type, GeometryValue):
        missing = [m for m in ("parse", "coerce", "from_json", "to_json") if not callable(getattr(type, m, None))]
        raise TypeError(f"a geometry parameter's type {type.__name__} has no {', '.join(missing)} (GeometryValue)")
    meta = dict(
        kind=kind,
        lo=lo,
        hi=hi,
        choices=tuple(choices or ()),
        optional=optional,
        symbol=symbol,
        help=help,
        step=step,
        type=type,
    )
    return field(default=default, metadata={"weft": meta})


@dataclass(frozen=True)
class Params:
    """Base of the per-method parameter dataclasses.

    Subclasses are ``@dataclass(frozen=True)`` with fields declared by :func:`param`; they may
    override :meth:`check` for rules that involve several parameters.
    """

    def __post_init__(self) -> None:
        for spec in specs(type(self)):
            value = spec.validate(getattr(self, spec.name))
            object.__setattr__(self, spec.name, value)
        self.check()

    def check(self) -> None:
        """Cross-parameter rules; raise ``InvalidParameter`` (see :func:`out_of_range`)."""

    def replace(self, **changes: Any) -> Self:
        unknown = set(changes) - {s.name for s in specs(type(self))}
        if unknown:
            raise InvalidParameter(_unknown_message(type(self), unknown))
        return dataclasses.replace(self, **changes)

    def to_dict(self) -> dict[str, Any]:
        """The JSON form (recipes, sessions): geometry written by its ``to_json``, sizes as lists."""
        out = {}
        for spec in specs(type(self)):
            v = getattr(self, spec.name)
            if spec.kind == "geometry" and v is not None:
                v = v.to_json()
            out[spec.name] = list(v) if isinstance(v, tuple) else v
        return out

    @classmethod
    def from_dict(cls, data: Mapping[str, Any], *, base: str | os.PathLike | None = None) -> Self:
        """Parameters from their JSON form; a geometry value is read by its type's ``from_json``
        (a file it names is found relative to ``base``, the recipe's folder)."""
        if not isinstance(data, Mapping):
            raise InvalidParameter(f"{cls.__name__}: parameters must be a JSON object, not {type(data).__name__}")
        by_name = {s.name: s for s in specs(cls)}
        unknown = set(data) - set(by_name)
        if unknown:
            raise InvalidParameter(_unknown_message(cls, unknown))
        values = dict(data)
        for name, value in values.items():
            spec = by_name[name]
            if spec.type is not None and value is not None and not isinstance(value, spec.type):
                values[name] = spec.type.from_json(value, name, base)
        return cls(**values)


def _unknown_message(cls: type, unknown: set) -> str:
    names = ", ".join(sorted(map(str, unknown)))
    known = ", ".join(s.name for s in specs(cls))
    return f"unknown parameter {names} for {cls.__name__} (known: {known})"


def specs(cls: type) -> tuple[Spec, ...]:
    """The :class:`Spec` of every declared parameter of a ``Params`` subclass, in field order.

    Parameters
    ----------
    cls : type
        A ``Params`` subclass.

    Returns
    -------
    tuple of Spec
        Cached on the class after the first call.
    """
    cached = cls.__dict__.get("_weft_specs")
    if cached is not None:
        return cached
    out = []
    for f in dataclasses.fields(cls):
        meta = f.metadata.get("weft")
        if meta is None:
            continue
        out.append(Spec(name=f.name, default=f.default, **meta))
    result = tuple(out)
    cls._weft_specs = result  # type: ignore[attr-defined]  # a per-class cache, read back through cls.__dict__
    return result


def as_rng(rng: None | int | np.random.Generator) -> np.random.Generator:
    """A numpy Generator from the ``rng`` argument every method takes.

    Parameters
    ----------
    rng : None, int or numpy.random.Generator
        ``None``: fresh entropy; an integer: a seeded PCG64 (the same seed gives the same pixels); a
        ``Generator`` is used as it is.

    Returns
    -------
    numpy.random.Generator

    Raises
    ------
    InvalidParameter
        ``rng`` is none of these (a bool is not a seed).
    """
    if rng is None or isinstance(rng, (int, np.integer)) and not isinstance(rng, bool):
        return np.random.default_rng(rng)
    if isinstance(rng, np.random.Generator):
        return rng
    raise InvalidParameter(f"parameter 'rng' = {rng!r} must be None, an integer seed or a numpy Generator", name="rng")
