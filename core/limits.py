"""Up-front limits: refuse a job that is too large before doing any of it.

Three checks, each one line when it refuses (``LimitError``, a ``WeftError``):

* :func:`check_output_size`: an output may not have more pixels than an input may
  (:func:`weft.core.image.get_max_pixels`, 50 Mpx unless ``WEFT_MAX_PIXELS`` says otherwise).
* :func:`check_memory`: a method's estimate of its peak memory must fit in the memory available
  (:func:`available_memory`: the system's, a container's control-group limit, ``ulimit -v``,
  whichever is smallest; no check where none can be read).
* :func:`check_duration`: a method's estimate of its running time on this machine must not exceed
  :func:`get_max_seconds` (10 minutes unless ``WEFT_MAX_SECONDS`` or :func:`set_max_seconds` says
  otherwise). Patch-search methods (quilting, NFPT) cost one or more DFTs of the whole source per
  block, so a small block on a large output from a large texture can take hours; they are refused
  with the estimate and what to change, instead of after minutes.

The estimates are models calibrated on a 2-core machine (figures in the README's performance
section); they are meant to be right within a factor of two or three, enough to tell ten minutes from
ten hours, not to predict seconds.
"""

from __future__ import annotations

import contextlib
import math
import os

from .errors import WeftError

#: Default longest estimated running time of one job, seconds.
DEFAULT_MAX_SECONDS = 600.0
_max_seconds_override: float | None = None

#: Seconds per (pixel x log2(pixels)) of one real 2-D DFT with OpenCV, float32, on a 2-core machine.
DFT_SECONDS_PER_UNIT = 1.2e-10


class LimitError(WeftError):
    """A job refused before it starts: too many pixels, too much memory or too long."""


def _positive(value: object, name: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) or value <= 0:
        raise WeftError(f"parameter '{name}' = {value!r} must be a positive number")
    return float(value)


def get_max_seconds() -> float:
    """The longest estimated running time a job may have.

    :func:`set_max_seconds` wins if called; else ``WEFT_MAX_SECONDS`` when it holds a positive number
    (``inf`` disables the check; invalid values are ignored); else :data:`DEFAULT_MAX_SECONDS`.
    """
    if _max_seconds_override is not None:
        return _max_seconds_override
    with contextlib.suppress(ValueError):
        if (value := float(os.environ.get("WEFT_MAX_SECONDS", "").strip())) > 0:
            return value
    return DEFAULT_MAX_SECONDS


def set_max_seconds(seconds: float | None) -> None:
    """Set the process-wide limit on estimated running time.

    Parameters
    ----------
    seconds : float or None
        The limit, > 0 (``inf``: no limit); ``None`` restores ``WEFT_MAX_SECONDS`` or the default.

    Raises
    ------
    WeftError
        ``seconds`` is not a positive number.
    """
    global _max_seconds_override
    _max_seconds_override = None if seconds is None else _positive(seconds, "max_seconds")


_PROC = "/proc"
_CGROUP_FS = "/sys/fs/cgroup"


def available_memory() -> int | None:
    """Bytes of memory a new allocation can have now, or ``None`` if unknown: the smallest of the
    system's ``MemAvailable`` (``/proc/meminfo``), the headroom under every memory limit of the
    control groups this process is in (cgroup v2 ``memory.max`` minus ``memory.current``, v1
    ``memory.limit_in_bytes`` minus ``memory.usage_in_bytes``; reclaimable file cache counted as
    free; the limits of parent groups apply too), and the address space left under ``ulimit -v``
    (``RLIMIT_AS`` minus this process's ``VmSize``)."""
    found = [v for v in (_meminfo_available(), _cgroup_available(), _address_space_left()) if v is not None]
    return max(0, min(found)) if found else None


def _meminfo_available() -> int | None:
    try:
        with open(os.path.join(_PROC, "meminfo"), encoding="ascii") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        return None
    return None


def _read_int(path: str) -> int | None:
    try:
        with open(path, encoding="ascii") as f:
            text = f.read(64).strip()
    except (OSError, UnicodeDecodeError):
        return None
    if text == "max":
        return None
    try:
        return int(text)
    except ValueError:
        return None


def _stat_value(path: str, key: str) -> int:
    try:
        with open(path, encoding="ascii") as f:
            for line in f:
                name, _, value = line.partition(" ")
                if name == key:
                    return int(value)
    except (OSError, ValueError, UnicodeDecodeError):
        pass
    return 0


def _cgroup_folders() -> list[tuple[str, int]]:
    """(folder, cgroup version) of every memory control group this process is in, and their parents
    as far as they are mounted here (inside a container the mount's root is the container's group)."""
    try:
        with open(os.path.join(_PROC, "self", "cgroup"), encoding="utf-8") as f:
            lines = f.read(1 << 16).splitlines()
    except (OSError, UnicodeDecodeError):
        return []
    folders = []
    for line in lines:
        parts = line.split(":", 2)
        if len(parts) != 3:
            continue
        _, controllers, path = parts
        if controllers == "":
            roots, version = [_CGROUP_FS, os.path.join(_CGROUP_FS, "unified")], 2
        elif "memory" in controllers.split(","):
            roots, version = [os.path.join(_CGROUP_FS, "memory")], 1
        else:
            continue
        rel = path.strip("/")
        for root in roots:
            steps = rel.split("/") if rel else []
            for depth in range(len(steps), -1, -1):
                folders.append((os.path.join(root, *steps[:depth]), version))
    return folders


def _cgroup_available() -> int | None:
    best = None
    for folder, version in _cgroup_folders():
        if version == 2:
            limit = _read_int(os.path.join(folder, "memory.max"))
            used = _read_int(os.path.join(folder, "memory.current"))
            cache = _stat_value(os.path.join(folder, "memory.stat"), "inactive_file")
        else:
            limit = _read_int(os.path.join(folder, "memory.limit_in_bytes"))
            used = _read_int(os.path.join(folder, "memory.usage_in_bytes"))
            cache = _stat_value(os.path.join(folder, "memory.stat"), "total_inactive_file")
        if limit is None or used is None or limit >= 2**60:  # v1 writes "no limit" as about 2**63
            continue
        left = limit - max(0, used - cache)
        best = left if best is None else min(best, left)
    return best


def _address_space_left() -> int | None:
    """Bytes of address space left under ``ulimit -v`` (``RLIMIT_AS``), or None without such a limit."""
    try:
        import resource

        soft = resource.getrlimit(resource.RLIMIT_AS)[0]
    except (ImportError, OSError, ValueError, AttributeError):
        return None
    if soft == resource.RLIM_INFINITY or soft < 0:
        return None
    return soft - _vm_size()


def address_space_limit() -> int | None:
    """``ulimit -v`` in bytes (the soft ``RLIMIT_AS``), or None when there is none."""
    try:
        import resource

        soft = resource.getrlimit(resource.RLIMIT_AS)[0]
    except (ImportError, OSError, ValueError, AttributeError):
        return None
    return None if soft == resource.RLIM_INFINITY or soft < 0 else int(soft)


def _vm_size() -> int:
    try:
        with open(os.path.join(_PROC, "self", "status"), encoding="ascii") as f:
            for line in f:
                if line.startswith("VmSize:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    return 0


def _duration(seconds: float) -> str:
    if seconds < 10:
        return f"{seconds:.1f} s"
    if seconds < 90:
        return f"{seconds:.0f} s"
    if seconds < 5400:
        return f"{seconds / 60:.0f} min"
    return f"{seconds / 3600:.1f} hours"


def _bytes(n: float) -> str:
    return f"{n / 2**30:.1f} GiB" if n >= 2**30 else f"{n / 2**20:.0f} MiB"


def check_output_size(width: int, height: int, source: str = "parameter 'size'") -> None:
    """Refuse an output of more pixels than the pixel limit (:func:`weft.core.image.get_max_pixels`).

    Parameters
    ----------
    width, height : int
        The output's size in pixels.
    source : str, default "parameter 'size'"
        What set the size, for the message.

    Raises
    ------
    LimitError
        ``width * height`` exceeds the limit; the message gives both and how to raise the limit.
    """
    from .image import get_max_pixels

    limit = get_max_pixels()
    if width * height > limit:
        raise LimitError(
            f"{source}: an output of {width}x{height} = {width * height / 1e6:.1f} megapixels "
            f"exceeds the limit of {limit / 1e6:g} megapixels (set WEFT_MAX_PIXELS to raise it)"
        )


def check_memory(nbytes: float, what: str, advice: str = "make the output smaller") -> None:
    """Refuse a job whose estimated peak memory exceeds the memory available now (:func:`available_memory`).

    Parameters
    ----------
    nbytes : float
        The job's estimated peak memory, bytes.
    what : str
        The job, for the message.
    advice : str, default "make the output smaller"
        What to change, for the message.

    Raises
    ------
    LimitError
        ``nbytes`` exceeds the memory available (nothing is refused when it is unknown).
    """
    available = available_memory()
    if available is not None and nbytes > available:
        raise LimitError(f"{what} needs about {_bytes(nbytes)} of memory, {_bytes(available)} is available: {advice}")


def check_duration(seconds: float, what: str, advice: str) -> None:
    """Refuse a job whose estimated running time exceeds :func:`get_max_seconds`.

    Parameters
    ----------
    seconds : float
        The job's estimated running time on the reference machine.
    what : str
        The job (sizes, counts), for the message.
    advice : str
        Which parameters shorten it, for the message.

    Raises
    ------
    LimitError
        ``seconds`` exceeds the limit; the message gives both and how to raise the limit.
    """
    limit = get_max_seconds()
    if seconds > limit:
        raise LimitError(
            f"{what} would take about {_duration(seconds)} (limit {_duration(limit)}): {advice}, "
            f"or set WEFT_MAX_SECONDS to allow it"
        )


def dft_seconds(h: int, w: int) -> float:
    """Estimated seconds of one real DFT of an ``h`` x ``w`` float32 image padded to OpenCV's optimal size.

    Parameters
    ----------
    h, w : int
        The image's height and width before padding.

    Returns
    -------
    float
        ``DFT_SECONDS_PER_UNIT * n * log2(n)`` with ``n`` the padded pixel count.
    """
    import cv2

    n = cv2.getOptimalDFTSize(int(h)) * cv2.getOptimalDFTSize(int(w))
    return DFT_SECONDS_PER_UNIT * n * math.log2(max(n, 2))
