"""Batches: one recipe applied to many images (the frames of an animation, a folder of photos).

A batch is a recipe plus one or more *over* inputs: lists of files that replace one input of the
recipe in turn (several lists zip together), and a *pattern* naming each output
(``out/{stem}.png``, ``frame_{index:04d}.png``). :func:`plan` turns that into :class:`Item` s, checking
everything that can be wrong about the batch as a whole before any work (exit status 2 on the
command line): the recipe, the lists, the pattern (unknown fields, two items with one output, an
output that would overwrite an input). :func:`run` then runs the items

* on a local process pool (``concurrent.futures.ProcessPoolExecutor``, spawned workers, each loading
  the method's kernels once) by default, or
* on a Dask distributed cluster when given a scheduler address (``pip install -e '.[cluster]'``),

through one code path: both pools run :func:`run_item` on each item and hand back an
:class:`Outcome`. An item runs exactly as ``weft run`` on its recipe (:mod:`weft.core.run`), so its output
is byte for byte the same, recipe chunk included. An item's failure (a corrupt frame) is that
item's: it becomes a failed outcome with a one-line reason and the batch goes on. Outputs are
written atomically; an item whose output already exists with the same recipe is skipped (a re-run
resumes an interrupted batch; ``force`` redoes it). A worker that dies mid-item (killed, out of
memory) has its items run again: Dask reschedules them itself; the local pool is restarted and
its unfinished items resubmitted, up to :data:`MAX_ATTEMPTS` times each.

Memory: before any work the largest item's estimate (``Method.memory``) times the number of
workers must fit in the memory available (:mod:`weft.core.limits`); a Dask worker's own memory limit
is checked against the estimate times its threads.

Importing this package imports neither Dask nor the method modules. :mod:`.prepare` holds what a
batch is and the checks before any work; :mod:`.execute` runs its items on a pool (:mod:`.local_pool`
or :mod:`.dask_pool`), whose workers run each one with :mod:`.worker`.
"""

from .dask_pool import CONNECT_TIMEOUT, SCHEDULER_ENV, DaskPool, scheduler_address
from .execute import IN_FLIGHT_PER_WORKER, MAX_ATTEMPTS, run
from .local_pool import LocalPool, default_workers
from .prepare import (
    IMAGE_EXTENSIONS,
    SAVE_EXTENSIONS,
    BatchProgress,
    Item,
    Outcome,
    Plan,
    Summary,
    check_memory,
    expand_over,
    item_memory,
    plan,
)
from .worker import WorkerDied, run_item, set_threads, warm_up

__all__ = [
    "BatchProgress",
    "CONNECT_TIMEOUT",
    "DaskPool",
    "IMAGE_EXTENSIONS",
    "IN_FLIGHT_PER_WORKER",
    "Item",
    "LocalPool",
    "MAX_ATTEMPTS",
    "Outcome",
    "Plan",
    "SAVE_EXTENSIONS",
    "SCHEDULER_ENV",
    "Summary",
    "WorkerDied",
    "check_memory",
    "default_workers",
    "expand_over",
    "item_memory",
    "plan",
    "run",
    "run_item",
    "scheduler_address",
    "set_threads",
    "warm_up",
]
