"""The Dask pool: a batch's items submitted to a Dask distributed scheduler, with the checks that
say in one line when the cluster cannot run them (see :mod:`weft.core.batch`)."""

from __future__ import annotations

import collections
import contextlib
import os
import secrets
import time
from collections.abc import Mapping

from ..errors import WeftError
from .prepare import Item, Outcome
from .worker import WorkerDied, _one_line, run_item, set_threads, warm_up

#: Environment variable naming a Dask scheduler when none is given.
SCHEDULER_ENV = "DASK_SCHEDULER_ADDRESS"
#: How long to try reaching a Dask scheduler before giving up.
CONNECT_TIMEOUT = "10s"
#: Environment variable: seconds to wait for a Dask scheduler to have a worker.
WORKER_TIMEOUT_ENV = "WEFT_DASK_WORKER_TIMEOUT"


def _worker_timeout() -> float:
    try:
        value = float(os.environ.get(WORKER_TIMEOUT_ENV, ""))
    except ValueError:
        return 30.0
    return value if value > 0 else 30.0


#: Seconds to wait for a Dask scheduler to have at least one worker (``WEFT_DASK_WORKER_TIMEOUT``).
WORKER_TIMEOUT = _worker_timeout()


def scheduler_address(given: str | None) -> str | None:
    """The Dask scheduler to use.

    Parameters
    ----------
    given : str or None
        The address given on the command line.

    Returns
    -------
    str or None
        ``given``, else ``DASK_SCHEDULER_ADDRESS``, else None (the local pool).
    """
    return given or os.environ.get(SCHEDULER_ENV) or None


def _dask_threads(totals: Mapping[str, int], dask_worker=None) -> None:
    """On a Dask worker: OpenCV threads = the host's cores / the threads all workers there run."""
    host = dask_worker.address.rsplit(":", 1)[0]
    set_threads(max(1, (os.cpu_count() or 1) // max(1, totals.get(host, 1))))


class DaskPool:
    """A Dask distributed client on ``address``: the items are ``client.submit(run_item, item)``."""

    def __init__(self, address: str, method: str):
        try:
            from distributed import Client
        except ImportError:
            raise WeftError("a scheduler address needs Dask: pip install -e '.[cluster]'") from None
        import logging

        # distributed logs a lost connection with tracebacks; weft says what happened in one line
        for name in ("distributed", "tornado"):
            logging.getLogger(name).setLevel(logging.CRITICAL + 1)
        self.address = address
        try:
            self.client = Client(address, timeout=CONNECT_TIMEOUT)
        except Exception as e:  # noqa: BLE001 - OSError, TimeoutError; TypeError/ValueError for tls:// without
            # certificates; ImportError for ucx:// without ucx-py
            raise WeftError(
                f"cannot reach the Dask scheduler at {address} ({type(e).__name__}: {_one_line(e)})"
            ) from None
        try:
            self.client.wait_for_workers(1, timeout=WORKER_TIMEOUT)
        except Exception:  # noqa: BLE001 - (TimeoutError, or the scheduler went away meanwhile)
            self.close()
            raise WeftError(
                f"the Dask scheduler at {address} has no workers (waited {WORKER_TIMEOUT:g} s; "
                f"set {WORKER_TIMEOUT_ENV} to wait longer)"
            ) from None
        self.method = method
        totals: dict[str, int] = collections.Counter()
        for addr, info in self.workers().items():
            totals[addr.rsplit(":", 1)[0]] += info.get("nthreads", 1)
        self.client.run(_dask_threads, dict(totals))

    def workers(self) -> dict:
        return (
            self.client.scheduler_info(n_workers=-1)["workers"]
            if self._takes_n()
            else self.client.scheduler_info()["workers"]
        )

    def _takes_n(self) -> bool:
        import inspect

        return "n_workers" in inspect.signature(self.client.scheduler_info).parameters

    @property
    def slots(self) -> int:
        return max(1, sum(w.get("nthreads", 1) for w in self.workers().values()))

    def ready(self) -> list[int]:
        """Load the method's kernels on every worker now; their process ids."""
        self.client.run(warm_up, self.method)
        return list(self.client.run(os.getpid).values())

    def submit(self, item: Item):
        return self.client.submit(run_item, item, pure=False, key=f"weft-item-{item.index}-{secrets.token_hex(4)}")

    def wait(self, futures, timeout: float):
        from distributed import wait

        try:
            done, _ = wait(list(futures), timeout=timeout, return_when="FIRST_COMPLETED")
        except Exception:  # noqa: BLE001 - a timeout, or the connection lost (run() checks lost())
            return set()
        return done

    def outcome(self, future) -> Outcome:
        """The item's outcome. A finished item's result lives on its worker: if that worker died
        before we fetched it, Dask recomputes it and would wait for a worker forever, so wait in
        short steps and give up once the cluster is gone (``WeftError`` saying why)."""
        from distributed import KilledWorker

        while True:
            try:
                return future.result(timeout=1)
            except KilledWorker:
                raise WorkerDied() from None
            except TimeoutError:
                reason = self.gone()
                if reason:
                    raise WeftError(reason) from None

    def after_death(self) -> None:
        pass  # Dask has already retried the item on other workers

    def idle_without_workers(self) -> float:
        """Seconds since the cluster was last seen with a worker (checked at most every second)."""
        now = time.monotonic()
        if now - getattr(self, "_checked", 0.0) >= 1.0:
            self._checked = now
            try:
                has = bool(self.workers())
            except Exception:  # noqa: BLE001 - the scheduler gone: lost() says so
                has = True
            if has or not hasattr(self, "_seen"):
                self._seen = now
        return now - self._seen

    def lost(self) -> bool:
        """Whether the connection to the scheduler is gone (the scheduler was stopped or killed)."""
        return getattr(self.client, "status", "running") not in ("running", "connecting", "newly-created")

    def gone(self) -> str | None:
        """Why no item can finish any more (the scheduler lost, or no worker for ``WORKER_TIMEOUT``
        seconds), or None while the cluster can still run them."""
        if self.lost():
            return f"the Dask scheduler at {self.address} was lost before it was done"
        if self.idle_without_workers() > WORKER_TIMEOUT:
            return f"the Dask scheduler at {self.address} had no workers left for {WORKER_TIMEOUT:g} s"
        return None

    def cancel(self, futures) -> None:
        with contextlib.suppress(Exception):
            self.client.cancel(list(futures))

    def close(self) -> None:
        with contextlib.suppress(Exception):
            self.client.close(timeout=5)
