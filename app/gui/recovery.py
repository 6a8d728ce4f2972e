"""Who owns which crash-recovery file: one recovery file per running studio window, each with a lock.

A window autosaves its unsaved edits to a file of its own, ``recovery-<host>-<pid>-<token>.weft.json``
in the recovery folder, beside a lock ``….weft.lock`` (JSON) naming its owner: the process id, the
host, the process's start time (so a reused process id is not taken for the owner) and the id of
the settings the window runs with. On start, a window offers only *orphans*: recovery files whose
owner is no longer running on this host and that were written with the same settings. A file of a
window that still runs (in this process or another) is never offered or removed; a file written
with other settings (another user's or another setup's, or from before the studio had settings
here: a first launch) is a stranger's and is left alone; a lock naming another host cannot be
checked, so that file is left alone too.

Taking an orphan (:func:`claim`) renames its lock first, so two windows that start at once never
both offer the same file.
"""

from __future__ import annotations

import json
import os
import socket
import time
import uuid
from dataclasses import dataclass
from pathlib import Path

from PySide6.QtCore import QStandardPaths
from weft.core.image import atomic_write_bytes

PREFIX = "recovery-"
SUFFIX = ".weft.json"
LOCK_SUFFIX = ".weft.lock"
SETTINGS_KEY = "recovery/settings_id"


def recovery_folder() -> Path:
    """Where recovery files live: ``WEFT_RECOVERY_DIR`` if set, else the app data folder."""
    folder = (
        os.environ.get("WEFT_RECOVERY_DIR")
        or QStandardPaths.writableLocation(QStandardPaths.StandardLocation.AppDataLocation)
        or str(Path.home() / ".weft")
    )
    return Path(folder)


def settings_id(settings) -> str:
    """The id of these settings (made and stored on their first use): recovery files written with
    other settings are strangers' and never offered."""
    value = str(settings.value(SETTINGS_KEY, "") or "")
    if not value:
        value = uuid.uuid4().hex
        settings.setValue(SETTINGS_KEY, value)
        settings.sync()  # (a window killed soon after must still have written it)
    return value


def _host() -> str:
    return socket.gethostname() or "localhost"


def process_started(pid: int) -> str | None:
    """The start time of process ``pid`` as the system counts it (Linux: ``/proc/PID/stat`` field 22),
    or None where that cannot be read."""
    try:
        text = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return None
    return text[text.rfind(")") + 2 :].split()[19]  # fields after the command name; 22nd of the line


def _pid_running(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # it exists, owned by someone else
        return True
    except OSError:
        return False
    return True


def lock_path(recovery: Path) -> Path:
    return recovery.with_name(recovery.name[: -len(SUFFIX)] + LOCK_SUFFIX)


@dataclass(frozen=True)
class Owner:
    """The owner of a recovery file, as its lock names it."""

    pid: int
    host: str
    started: str | None
    settings: str

    @classmethod
    def me(cls, settings: str) -> Owner:
        return cls(os.getpid(), _host(), process_started(os.getpid()), settings)

    def to_bytes(self) -> bytes:
        return json.dumps(
            {"pid": self.pid, "host": self.host, "started": self.started, "settings": self.settings}
        ).encode("utf-8")

    @classmethod
    def read(cls, lock: Path) -> Owner | None:
        """The owner a lock names, or None if it is missing or unreadable."""
        try:
            data = json.loads(lock.read_text(encoding="utf-8"))
            return cls(int(data["pid"]), str(data["host"]), data.get("started"), str(data["settings"]))
        except (OSError, ValueError, KeyError, TypeError):
            return None

    def running(self) -> bool:
        """True if this owner may still run: on another host (it cannot be checked), or a live
        process here whose start time matches."""
        if self.host != _host():
            return True
        if not _pid_running(self.pid):
            return False
        started = process_started(self.pid)
        return started is None or self.started is None or started == self.started


def new_recovery_file(folder: Path) -> Path:
    """A recovery file name no other window uses."""
    safe_host = "".join(c if c.isalnum() or c in "-_" else "_" for c in _host())[:40]
    return folder / f"{PREFIX}{safe_host}-{os.getpid()}-{uuid.uuid4().hex[:8]}{SUFFIX}"


def write_lock(recovery: Path, owner: Owner) -> None:
    """(Any thread.) Say that ``owner`` owns ``recovery`` (atomically)."""
    atomic_write_bytes(lock_path(recovery), owner.to_bytes())


def orphans(folder: Path, settings: str) -> list[Path]:
    """The recovery files in ``folder`` that this window may offer: written with these settings,
    their owner no longer running; the newest first."""
    found = []
    try:
        candidates = list(folder.glob(f"{PREFIX}*{SUFFIX}"))
    except OSError:
        return []
    for path in candidates:
        owner = Owner.read(lock_path(path))
        if owner is None or owner.settings != settings or owner.running():
            continue
        try:
            found.append((path.stat().st_mtime, path))
        except OSError:
            continue
    return [p for _, p in sorted(found, reverse=True)]


def claim(recovery: Path, me: Owner) -> bool:
    """Take an orphan for this window: its lock is renamed away (only one process can), checked
    again, and written naming ``me``. False if another window took it first or its owner runs."""
    lock = lock_path(recovery)
    held = lock.with_name(f"{lock.name}.{uuid.uuid4().hex[:8]}")
    try:
        os.rename(lock, held)
    except OSError:
        return False
    owner = Owner.read(held)
    if owner is None or owner.settings != me.settings or owner.running():
        try:  # (taken by a window that started meanwhile: give it back)
            os.rename(held, lock)
        except OSError:
            pass
        return False
    try:
        write_lock(recovery, me)
    finally:
        held.unlink(missing_ok=True)
    return True


def modified(recovery: Path) -> str:
    """When ``recovery`` was last written, in words for the question ("today 14:02")."""
    try:
        t = recovery.stat().st_mtime
    except OSError:
        return ""
    day = (
        "today"
        if time.strftime("%Y%m%d", time.localtime(t)) == time.strftime("%Y%m%d")
        else time.strftime("%d %b", time.localtime(t))
    )
    return f"{day} {time.strftime('%H:%M', time.localtime(t))}"
