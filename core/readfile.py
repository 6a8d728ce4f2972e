"""Reading a file safely, naming it safely, and telling whether two paths are one file.

Every file weft reads (images, recipes, sessions, feature lines, views, masks) is opened through
:func:`open_regular`: a named pipe, a device or a socket is refused at once (reading one could block
forever or never end), and :func:`read_regular` reads at most a given number of bytes. Names go into
messages through :func:`shown`, so a name with a newline or an escape sequence stays on one line and
never reaches the terminal raw. :func:`file_key` identifies a file by device and inode, so an output is
never written over an input reached through another path (a bind mount, a share mounted twice, a
symbolic or hard link).
"""

from __future__ import annotations

import os
import stat
from typing import IO

from .errors import WeftError

_KINDS = (
    (stat.S_ISFIFO, "a named pipe (FIFO)"),
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
    (stat.S_ISSOCK, "a socket"),
    (stat.S_ISDIR, "a directory"),
)


def shown(path: str | os.PathLike | bytes) -> str:
    """``path`` as text for a one-line message.

    Parameters
    ----------
    path : str, os.PathLike or bytes
        A file name.

    Returns
    -------
    str
        The path as it is when every character is printable, else quoted the way Python writes a
        string (``'a\\nb.png'``, ``'\\x1b]0;x.png'``).
    """
    text = os.fsdecode(path) if isinstance(path, (bytes, os.PathLike)) else str(path)
    return text if text.isprintable() else repr(text)


def one_line(text: str) -> str:
    """``text`` with every character that is not printable escaped.

    A message's last line of defence: a newline, a carriage return or an escape sequence never reaches
    the terminal.

    Parameters
    ----------
    text : str
        A message.

    Returns
    -------
    str
        The message on one line.
    """
    if text.isprintable():
        return text
    return "".join(c if c.isprintable() else repr(c)[1:-1] for c in text)


def kind_of(mode: int) -> str | None:
    """What a file of this ``st_mode`` is when it is not a regular file.

    Parameters
    ----------
    mode : int
        An ``os.stat`` mode.

    Returns
    -------
    str or None
        Words such as ``"a named pipe (FIFO)"``, ``"a character device"``, ``"a directory"``; None for
        a regular file.
    """
    for test, name in _KINDS:
        if test(mode):
            return name
    return None if stat.S_ISREG(mode) else "not a regular file"


class NotRegularFile(WeftError):
    """A path that is a named pipe, a device, a socket or a folder where a file was expected."""


def open_regular(path: str | os.PathLike, what: str = "file", *, error: type[WeftError] = NotRegularFile) -> IO[bytes]:
    """Open ``path`` for reading in binary, refusing anything but a regular file without blocking.

    The path is checked before it is opened (a device is never opened) and the open file again
    (``O_NONBLOCK``: a named pipe without a writer cannot hold the open up), so nothing swapped in
    between is read.

    Parameters
    ----------
    path : str or os.PathLike
        The file.
    what : str, default "file"
        What it should be, for the message (``"recipe"``, ``"image"``).
    error : type of WeftError, default NotRegularFile
        The error raised for a path that is not a regular file.

    Returns
    -------
    file object
        Open for binary reading.

    Raises
    ------
    OSError
        The file is missing, unreadable, a symbolic link loop, ... (the caller words these);
        ``IsADirectoryError`` for a folder.
    error
        ``{path}: is a named pipe (FIFO), not a {what}`` (and the like), one line.
    """
    name = os.fsdecode(path)
    kind = kind_of(os.stat(name).st_mode)
    if kind is not None and kind != "a directory":
        raise error(f"{shown(name)}: is {kind}, not {_a(what)}")
    if kind == "a directory":
        raise IsADirectoryError(21, "Is a directory", name)
    fd = os.open(name, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0))
    try:
        mode = os.fstat(fd).st_mode
        kind = kind_of(mode)
        if kind == "a directory":
            raise IsADirectoryError(21, "Is a directory", name)
        if kind is not None:
            raise error(f"{shown(name)}: is {kind}, not {_a(what)}")
        if hasattr(os, "set_blocking"):
            os.set_blocking(fd, True)
        return open(fd, "rb")
    except BaseException:
        os.close(fd)
        raise


def read_regular(
    path: str | os.PathLike, limit: int, what: str = "file", *, error: type[WeftError] = NotRegularFile
) -> bytes:
    """The bytes of the regular file ``path`` (see :func:`open_regular`), at most ``limit`` of them.

    Parameters
    ----------
    path : str or os.PathLike
        The file.
    limit : int
        The largest size read, bytes.
    what : str, default "file"
        What it should be, for the message.
    error : type of WeftError, default NotRegularFile
        The error raised for a path that is not a regular file or is too large.

    Returns
    -------
    bytes

    Raises
    ------
    OSError
        As :func:`open_regular`.
    error
        Not a regular file; or larger than ``limit`` (``{path}: 12.0 MB is too large for a {what}
        (the limit is 10 MB); not read``), also when it grows past it while being read.
    """
    name = os.fsdecode(path)
    with open_regular(name, what, error=error) as f:
        size = os.fstat(f.fileno()).st_size
        if size > limit:
            raise error(
                f"{shown(name)}: {_size(size)} is too large for {_a(what)} (the limit is {_size(limit)}); not read"
            )
        data = f.read(limit + 1)
    if len(data) > limit:
        raise error(f"{shown(name)}: too large for {_a(what)} (the limit is {_size(limit)}); not read")
    return data


def _a(what: str) -> str:
    return ("an " if what[:1].lower() in "aeiou" else "a ") + what


def _size(n: int) -> str:
    return f"{n / 2**20:.1f} MB" if n % 2**20 else f"{n // 2**20} MB"


def file_key(path: str | os.PathLike) -> tuple:
    """What identifies the file ``path`` names, whichever path names it.

    An existing file: its device and inode (``os.stat``, following links), the identity
    :func:`os.path.samefile` compares. A file not yet there: its folder's device and inode and its
    name, so two spellings of one new output (through a bind mount, ``..``, a link to the folder)
    still compare equal. A path whose folder is not there either: its absolute, normalised text.

    Parameters
    ----------
    path : str or os.PathLike
        A file that exists or is about to be written.

    Returns
    -------
    tuple
        Equal for two paths of the same file.
    """
    name = os.path.abspath(os.fsdecode(path))
    try:
        st = os.stat(name)
        return ("file", st.st_dev, st.st_ino)
    except (OSError, ValueError):
        pass
    folder, base = os.path.split(name)
    try:
        st = os.stat(folder)
        return ("new", st.st_dev, st.st_ino, base)
    except (OSError, ValueError):
        return ("path", os.path.normpath(name))


def same_file(a: str | os.PathLike, b: str | os.PathLike) -> bool:
    """Whether ``a`` and ``b`` name one file (or one file to be), by :func:`file_key`.

    Parameters
    ----------
    a, b : str or os.PathLike
        Paths.

    Returns
    -------
    bool
    """
    return file_key(a) == file_key(b)
