"""The temporary files of :func:`weft.core.image.atomic_write_bytes`: their names say which process
of which machine writes them, so a later run can remove those a killed writer left behind."""

from __future__ import annotations

import os
import re
import stat
import time
import zlib

#: A temporary file of :func:`atomic_write_bytes` untouched this long is a dead writer's, whoever wrote it.
STALE_TEMPORARY_SECONDS = 600.0


def _writer_tag() -> str:
    """This process on this machine, in a temporary file's name: ``{host hash}-{pid}``."""
    import socket

    return f"{zlib.crc32(socket.gethostname().encode('utf-8', 'replace')):08x}-{os.getpid()}"


def remove_stale_temporaries(paths) -> list[str]:
    """Remove what a killed :func:`atomic_write_bytes` left beside the given output paths.

    Their ``.{name}.XXXXXXXX[.{host}-{pid}].tmp`` files whose writer is gone are removed: written by a
    process of this machine that no longer runs, or untouched for :data:`STALE_TEMPORARY_SECONDS` (a
    writer elsewhere, or an older weft). Another writer's file in progress is left alone. Never raises.

    Parameters
    ----------
    paths : iterable of str or os.PathLike
        The outputs whose folders are looked through.

    Returns
    -------
    list of str
        The removed paths.
    """
    host = _writer_tag().split("-")[0]
    by_folder: dict[str, set[str]] = {}
    for p in paths:
        folder, name = os.path.split(os.path.abspath(os.fsdecode(p)))
        by_folder.setdefault(folder, set()).add(name)
    removed = []
    now = time.time()
    for folder, names in by_folder.items():
        try:
            entries = os.listdir(folder)
        except OSError:
            continue
        for entry in entries:
            m = _TEMPORARY.match(entry)
            if m is None or m.group(1) not in names:
                continue
            full = os.path.join(folder, entry)
            try:
                st = os.lstat(full)
                if not stat.S_ISREG(st.st_mode):
                    continue
                dead = m.group(2) == host and not _running(int(m.group(3)))
                if dead or now - st.st_mtime > STALE_TEMPORARY_SECONDS:
                    os.unlink(full)
                    removed.append(full)
            except OSError:
                continue
    return removed


_TEMPORARY = re.compile(r"^\.(.+)\.[A-Za-z0-9_]{8}(?:\.([0-9a-f]{8})-([0-9]+))?\.tmp$", re.DOTALL)


def _running(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OSError, OverflowError):
        return True
    return True
