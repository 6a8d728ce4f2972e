"""The error classes every front end turns into one clear line.

``WeftError`` derives from ``ValueError`` so callers that already catch bad values keep working.
The CLI prints ``str(error)`` on stderr and exits with status 2; the GUI shows it and keeps its
previous result. Messages name what is wrong (the parameter, the file, the line) and the allowed
values; they never carry a traceback.
"""

from __future__ import annotations


class WeftError(ValueError):
    """Base of every error caused by user input (a file, a parameter, a geometry).

    ``input`` names the method input (e.g. ``"texture"``) the error is about when it concerns one
    image, such as a block that does not fit it; a front end that knows the file behind that input
    names it (the CLI prefixes the path).
    """

    input: str | None = None


class InvalidParameter(WeftError):
    """A parameter is of the wrong type or outside its allowed range.

    ``name`` is the parameter's name, ``value`` the offending value.
    """

    def __init__(self, message: str, *, name: str | None = None, value: object = None):
        super().__init__(message)
        self.name = name
        self.value = value


class ImageError(WeftError):
    """An image cannot be read, written or used (corrupt, too large, wrong shape)."""

    def __init__(self, message: str, *, path: str | None = None):
        super().__init__(message)
        self.path = path


class GeometryError(WeftError):
    """Feature lines, quads or prototype rectangles that do not define a usable geometry."""


class Cancelled(Exception):
    """Raised inside a job when its ``CancelToken`` was cancelled.

    Not a ``WeftError``: cancelling is not a mistake, and front ends treat it silently.
    """
