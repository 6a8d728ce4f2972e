"""numba kernels (njit, cache=True, nogil=True), one module per method.

Importing this package (which every kernel module does first) prepares numba's on-disk cache and
reports compilations; it is the only place that knows about numba's caching machinery:

* **A cache folder that always works.** numba looks for a writable cache folder in turn: the
  folder ``NUMBA_CACHE_DIR`` names, the package's own ``__pycache__``, then the user's cache folder
  (``~/.cache/numba``); when none is writable — a shared read-only install used with
  ``HOME=/nonexistent``, as on some render nodes — decorating a kernel raises ``RuntimeError: cannot
  cache function ...: no locator available`` and every numba method fails. We add a last folder to
  that list: ``weft-numba-<uid>`` in the system's temporary folder, private to the user (created
  0700; one owned by someone else, or open to others, is refused: numba's cache files are pickles,
  loading a planted one would run its code). The user-wide and the temporary folder are seeded
  from the package's own ``__pycache__`` (what ``weft warm-up`` wrote there at install time), so a
  read-only install that was warmed up stays warm for every user. If even that fails, the kernels are compiled without a
  cache (every run pays the compile) and :func:`weft.core.compiles.kernel_cache_notice` says so in one
  line for the front ends to show.
* **Safe concurrent saves.** numba's cache saves a new signature by rewriting the function's index
  and a numbered data file, without a lock; weft takes a file lock around each save (POSIX), so
  processes compiling at once (``weft warm-up``'s workers) cannot cross their files.
* **Damaged cache files are repaired.** An index or data file that cannot be read back (cut short
  by a power cut) would make every run of its method fail with ``EOFError: Ran out of input``, and
  ``weft warm-up`` too; such files are removed, the kernel is compiled again and saved, and
  :func:`weft.core.compiles.kernel_cache_repairs` says so in one line.
* **Compile events.** numba announces every real compilation (a cache miss, never a cache load) as
  a ``numba:compile`` event; we forward their start and end to :mod:`weft.core.compiles`, which lets a
  front end say "preparing ... — first run only" exactly while a compile happens, and leave the
  compile out of a render's time.
"""

from __future__ import annotations

import os
import shutil
import stat
import tempfile
import threading

from numba.core import caching as _caching
from numba.core import dispatcher as _dispatcher
from numba.core import event as _event

from .. import compiles as _compiles

_FALLBACK_PREFIX = "weft-numba-"


def fallback_cache_root() -> str:
    """The per-user cache folder used when numba finds no writable one of its own."""
    uid = os.getuid() if hasattr(os, "getuid") else os.getlogin()
    return os.path.join(tempfile.gettempdir(), f"{_FALLBACK_PREFIX}{uid}")


def _private_folder(path: str) -> bool:
    """Create ``path`` (0700) if needed; True if it is a folder that only this user controls."""
    try:
        os.makedirs(path, mode=0o700, exist_ok=True)
        st = os.lstat(path)
    except OSError:
        return False
    if not stat.S_ISDIR(st.st_mode):
        return False
    if hasattr(os, "getuid") and (st.st_uid != os.getuid() or st.st_mode & 0o022):
        return False  # someone else's, or writable by others: its pickles cannot be trusted
    return True


def _seed_from_tree(py_file: str, cache_path: str) -> None:
    """Copy the cache files of ``py_file``'s kernels from the package's own ``__pycache__`` (written
    there by ``weft warm-up`` run by whoever installed weft, when that folder was writable for them)
    into ``cache_path``, unless already there: a read-only install then still starts warm. numba
    checks each index against the source's hash, so a stale copy is simply ignored."""
    tree = os.path.join(os.path.dirname(py_file), "__pycache__")
    prefix = os.path.splitext(os.path.basename(py_file))[0] + "."
    try:
        names = [n for n in os.listdir(tree) if n.startswith(prefix) and n.endswith((".nbi", ".nbc"))]
    except OSError:
        return
    for name in names:
        target = os.path.join(cache_path, name)
        if os.path.exists(target):
            continue
        try:
            shutil.copyfile(os.path.join(tree, name), target + ".seed")
            os.replace(target + ".seed", target)
        except OSError:
            return


class UserWideCacheLocator(_caching.UserWideCacheLocator):
    """numba's user-wide cache folder (``~/.cache/numba``), seeded from the package's own cache."""

    @classmethod
    def from_function(cls, py_func, py_file):
        self = super().from_function(py_func, py_file)
        if self is not None:
            _seed_from_tree(py_file, self.get_cache_path())
        return self


class TempCacheLocator(_caching.UserProvidedCacheLocator):
    """numba's last cache folder: :func:`fallback_cache_root`, one sub-folder per source folder (as
    ``NUMBA_CACHE_DIR`` would be laid out)."""

    def __init__(self, py_func, py_file):
        self._py_file = py_file
        self._lineno = py_func.__code__.co_firstlineno
        self._cache_path = os.path.join(fallback_cache_root(), self.get_suitable_cache_subpath(py_file))

    @classmethod
    def from_function(cls, py_func, py_file):
        if not os.path.exists(py_file) or not _private_folder(fallback_cache_root()):
            return None
        self = cls(py_func, py_file)
        try:
            self.ensure_cache_path()
        except OSError:
            return None
        _seed_from_tree(py_file, self.get_cache_path())
        return self


def _install_fallback_locator() -> None:
    classes = _caching.CacheImpl._locator_classes
    if _caching.UserWideCacheLocator in classes:
        classes[classes.index(_caching.UserWideCacheLocator)] = UserWideCacheLocator
    if TempCacheLocator not in classes:
        classes.append(TempCacheLocator)  # after numba's own: used only when they all fail


_NO_CACHE_NOTICE = (
    "numba can write its cache nowhere (NUMBA_CACHE_DIR, the package folder, the home "
    "folder and {tmp} are not writable): kernels are compiled on every run"
)
_original_enable_caching = _dispatcher.Dispatcher.enable_caching


def _enable_caching_or_not(self):
    """``Dispatcher.enable_caching`` that leaves a kernel uncached (numba's ``NullCache``) instead of
    raising when no cache folder is usable at all."""
    try:
        _original_enable_caching(self)
    except RuntimeError as e:
        if "no locator available" not in str(e):
            raise
        self._cache = _caching.NullCache()
        _compiles.note_kernel_cache(_NO_CACHE_NOTICE.format(tmp=fallback_cache_root()))


def _install_no_cache_fallback() -> None:
    if _dispatcher.Dispatcher.enable_caching is not _enable_caching_or_not:
        _dispatcher.Dispatcher.enable_caching = _enable_caching_or_not  # type: ignore[method-assign]  # a patch of numba


_original_save = _caching.IndexDataCacheFile.save


def _save_locked(self, key, data):
    """``IndexDataCacheFile.save`` under an exclusive lock on the function's index: numba reads the
    index, picks the first free data-file number and writes both, so two processes saving two
    signatures of one function at once (``weft warm-up``'s workers, or a render farm's first jobs)
    could leave the index naming the other one's data file — compiled code for the wrong types."""
    try:
        import fcntl

        lock = open(os.path.join(self._cache_path, self._index_name + ".lock"), "a")
    except (ImportError, OSError):  # no POSIX locks here, or no writing: numba's own behaviour
        return _original_save(self, key, data)
    with lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        return _original_save(self, key, data)


def _install_save_lock() -> None:
    if _caching.IndexDataCacheFile.save is not _save_locked:
        _caching.IndexDataCacheFile.save = _save_locked  # type: ignore[method-assign]  # a patch of numba


_DAMAGED_NOTICE = "numba's cache of {what} could not be read (damaged: {why}); it was dropped and compiled again"


def _drop_damaged(cache_file, error: BaseException) -> None:
    """Remove a function's cache files (its index and every data file) that could not be read (cut
    short by a power cut, overwritten) and say so once; numba then compiles and saves it afresh."""
    base = cache_file._index_name[: -len(".nbi")]
    try:
        names = [
            n
            for n in os.listdir(cache_file._cache_path)
            if n == cache_file._index_name or (n.startswith(base + ".") and n.endswith(".nbc"))
        ]
    except OSError:
        names = []
    for name in names:
        try:
            os.unlink(os.path.join(cache_file._cache_path, name))
        except OSError:
            pass
    what = base.split("-")[0]
    _compiles.note_kernel_cache_repair(_DAMAGED_NOTICE.format(what=what, why=type(error).__name__))


_original_load_index = _caching.IndexDataCacheFile._load_index
_original_load_data = _caching.IndexDataCacheFile._load_data
_original_load_overload = _caching.Cache.load_overload


def _load_index_or_drop(self):
    """numba's ``_load_index``, but an index that cannot be unpickled (``EOFError: Ran out of input``
    for a truncated file) is dropped and read as empty, instead of failing every run for good."""
    try:
        return _original_load_index(self)
    except (OSError, MemoryError):
        raise
    except Exception as e:  # noqa: BLE001 - a damaged pickle raises many kinds
        _drop_damaged(self, e)
        return {}


def _load_data_or_drop(self, name):
    """numba's ``_load_data``; a data file that cannot be unpickled is dropped with its index and
    reported to numba as missing (``OSError``), which it treats as a cache miss."""
    try:
        return _original_load_data(self, name)
    except (OSError, MemoryError):
        raise
    except Exception as e:  # noqa: BLE001
        _drop_damaged(self, e)
        raise OSError(f"damaged cache file {name}") from None


def _load_overload_or_drop(self, sig, target_context):
    """``Cache.load_overload``; an entry that unpickles but cannot be rebuilt into code is dropped
    (and compiled again by the caller, as for any cache miss)."""
    try:
        return _original_load_overload(self, sig, target_context)
    except (OSError, MemoryError):
        raise
    except Exception as e:  # noqa: BLE001
        _drop_damaged(self._cache_file, e)
        return None


def _install_cache_repair() -> None:
    if _caching.IndexDataCacheFile._load_index is not _load_index_or_drop:
        # patches of numba's cache classes
        _caching.IndexDataCacheFile._load_index = _load_index_or_drop  # type: ignore[method-assign]
        _caching.IndexDataCacheFile._load_data = _load_data_or_drop  # type: ignore[method-assign]
        _caching.Cache.load_overload = _load_overload_or_drop  # type: ignore[method-assign]


class _CompileListener(_event.Listener):
    """Forwards numba's ``numba:compile`` events to :mod:`weft.core.compiles`, saying which are a thread's outermost
    (a kernel compiles the kernels it calls inside its own compile)."""

    def __init__(self):
        self._depth = threading.local()

    def on_start(self, event):
        depth = getattr(self._depth, "n", 0)
        self._depth.n = depth + 1
        _compiles.compile_started(outermost=depth == 0)

    def on_end(self, event):
        depth = getattr(self._depth, "n", 1) - 1
        self._depth.n = depth
        _compiles.compile_ended(outermost=depth == 0)


_install_fallback_locator()
_install_no_cache_fallback()
_install_save_lock()
_install_cache_repair()
if not getattr(_compiles, "_compile_listener_installed", False):
    _event.register("numba:compile", _CompileListener())
    _compiles._compile_listener_installed = True  # type: ignore[attr-defined]  # set once per process
