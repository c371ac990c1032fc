"""Running independent simulation batches in parallel: local processes or a Dask cluster.

Rollouts of a plan (:mod:`arrange_up.evaluation.evaluate`), and later other embarrassingly parallel
batches (training data for learned transition models, benchmarks), go through one small
abstraction, a :class:`Runner`::

    runner = get_runner("local", workers=2)        # or get_runner("dask", scheduler="tcp://…")
    for item, result in runner.map(fn, items, chunksize=25):
        ...                                        # in completion order, as chunks finish

``fn`` takes one item and returns one result; it and the items must be picklable (a module-level
function, or a :func:`functools.partial` of one). Items are sent in chunks of ``chunksize`` (one
task per chunk) to amortise the per-task overhead; every chunk's ``(item, result)`` pairs are
yielded as soon as that chunk finishes, so callers can record results at once and show
progress. Results arrive in completion order, not item order: callers that need determinism
make each result depend on its item only (the rollouts seed each one from ``(seed, index)``).

Backends
========
* ``"local"`` with one worker: :class:`SerialRunner` runs everything in this process, one item
  at a time (no pool, no pickling; each result is yielded as it is computed).
* ``"local"`` with more: :class:`LocalRunner`, joblib's loky process pool
  (:func:`local_executor`, ``joblib.externals.loky.get_reusable_executor``), fed chunk by chunk
  (at most two tasks per worker in flight) and read with ``concurrent.futures.wait``. loky keeps
  one executor per process and hands the same one to every caller that asks with the same
  arguments, so only the first batch pays the pool's start-up (the workers' imports dominate
  it); the particle semantics (and through it the fixture repair), the planner's successor
  sessions (:mod:`arrange_up.planning.successors`) and the rollouts share it; it is the
  process's only worker pool. Idle workers are reaped after :data:`IDLE_TIMEOUT`
  seconds and respawned by the next batch. Each worker watches its parent
  (:func:`_end_with_parent`) and ends within :data:`PARENT_POLL` seconds of the parent's
  death, even a SIGKILL that gives the parent no chance to stop its pool, and one that comes
  while the workers still start (they end as their start-up does). Workers ignore
  SIGINT (:func:`_init_worker`): interrupting is the parent's; interrupting a batch cancels
  its queued tasks and leaves the pool up. (Not ``joblib.Parallel``: its
  executor wrapper cannot take over an executor that ``get_reusable_executor`` created, so
  mixing the two in one process fails with ``AttributeError: _temp_folder_manager``.)
* ``"dask"``: :class:`DaskRunner`, a ``dask.distributed`` client. With no ``scheduler`` address
  it starts (once per process and worker count, kept for later batches, closed at exit) a
  ``LocalCluster(n_workers=workers, threads_per_worker=1, processes=True)``; with an address it
  connects ``Client(scheduler)`` to an existing cluster, whose workers must have arrange-up
  installed. Tasks go directly through the client (``submit`` and ``as_completed``), not
  through joblib's Dask backend: the function (which carries the problem and plan) is
  scattered to every worker once, the number of tasks in flight is bounded (four per worker),
  and an interrupted batch cancels its queued tasks without tearing the cluster down. dask is
  imported only here, and only when this backend is asked for; without it
  :class:`BackendUnavailableError` says to ``pip install "arrange-up[dask]"``.

Sessions
========
``map`` suits a batch known in advance. A search learns its work one step at a time and
needs each answer on demand, so :meth:`Runner.session` opens a :class:`Session` instead::

    session = runner.session(fn, context)     # fn(context, item) -> result, module-level
    pending = session.submit(item)            # starts the work (SerialRunner: on result())
    result = pending.result()                 # waits; the same value for any backend
    pending.withdraw()                        # True: dropped before it started (local only)

``context`` (the problem and what the worker builds from it) is shipped to each worker once,
not with every task: Dask scatters it to every worker (``broadcast=True``); a local worker
keeps the contexts it has unpickled, by digest, and a task that meets a worker without it is
sent again with the pickle (so a worker respawned after :data:`IDLE_TIMEOUT` gets it again).
A task lost with its worker (a crashed loky process, a Dask worker gone, its data lost) is
submitted again, up to :data:`RETRIES` times; since results depend on ``(context, item)``
only, a retried task gives the result the first attempt would have. Past the retries, and in
:meth:`Runner.map` at once (a broken loky pool fails every task in flight; a lost Dask
scheduler cancels them all), a lost worker raises :class:`WorkersLostError`, one line, in place
of the library's exception.

:func:`get_runner` caches runners, so repeated batches in one process reuse the same pool or
cluster; :func:`shutdown` closes the cached Dask clients and clusters (the local pool is
joblib's and reaps itself).
"""

from __future__ import annotations

import atexit
import hashlib
import logging
import math
import os
import pickle
import signal
import threading
import time
from collections import OrderedDict
from collections.abc import Callable, Generator, Iterable, Iterator, Sequence
from concurrent.futures import FIRST_COMPLETED, wait
from dataclasses import dataclass
from itertools import islice
from typing import Any, Generic, TypeVar

from arrange_up.counts import check_count

__all__ = [
    "BACKENDS",
    "BackendUnavailableError",
    "WorkersLostError",
    "DaskRunner",
    "LocalRunner",
    "Pending",
    "Runner",
    "SerialRunner",
    "Session",
    "available_cores",
    "check_runner_options",
    "get_runner",
    "check_workers",
    "local_executor",
    "local_workers_lost",
    "max_workers",
    "shutdown",
]

T = TypeVar("T")
R = TypeVar("R")

BACKENDS: tuple[str, ...] = ("local", "dask")
DASK_INSTALL_HINT = 'pip install "arrange-up[dask]"'


class BackendUnavailableError(RuntimeError):
    """A backend was asked for whose libraries are not installed (or that cannot be reached)."""


class WorkersLostError(RuntimeError):
    """A batch cannot go on: its workers are gone (a local worker process killed or out of
    memory, which breaks loky's pool; a Dask scheduler or worker lost, which cancels the
    tasks). Raised by :meth:`Runner.map` in place of the library's exception (loky's
    ``TerminatedWorkerError``, distributed's ``FutureCancelledError``, ...), and by a
    session's :meth:`Pending.result` once its retries are spent; the message is one line
    saying what was lost. The pairs :meth:`Runner.map` yielded before it stand: a caller
    that recorded them (an evaluation's record file) keeps them, and says how to go on."""


def local_workers_lost(error: BaseException) -> WorkersLostError:
    """The one-line :class:`WorkersLostError` for a broken local pool ``error`` (loky's
    ``TerminatedWorkerError`` or another ``BrokenProcessPool``)."""
    return WorkersLostError(
        "a local worker process ended abruptly (killed, or out of memory), which broke the "
        f"process pool ({type(error).__name__})"
    )


def _dask_workers_lost(error: BaseException) -> WorkersLostError:
    reason = " ".join(str(error).split())  # distributed's messages may span lines
    return WorkersLostError(
        "the Dask cluster lost the batch's tasks (its scheduler or workers are gone): "
        f"{type(error).__name__}{': ' + reason if reason else ''}"
    )


def available_cores() -> int:
    """Cores this process may run on (``os.sched_getaffinity``), at least 1."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover - not on Linux
        return os.cpu_count() or 1


#: Worker processes allowed per core this process may use (:func:`max_workers`). The work is
#: simulation, bound by the CPU: beyond one process per core more only compete for the cores
#: and for memory (every worker imports numpy, shapely and pymunk), and a
#: mistyped count (``--workers 1024``) would start hundreds of processes. Four per core leave
#: room for overlapping start-up and I/O.
WORKERS_PER_CORE = 4


def max_workers() -> int:
    """The most worker processes a runner starts here: :data:`WORKERS_PER_CORE` per core this
    process may use (:func:`available_cores`)."""
    return WORKERS_PER_CORE * available_cores()


def check_workers(workers: Any) -> None:
    """Raise ``ValueError`` unless ``workers`` is a positive integer of at most
    :func:`max_workers`; the message names the limit and why it exists."""
    check_count("workers", workers)
    limit = max_workers()
    if workers > limit:
        cores = available_cores()
        raise ValueError(
            f"workers must be at most {limit} ({WORKERS_PER_CORE} per core, {cores} "
            f"core{'s' if cores != 1 else ''} here), got {workers}: more processes than "
            "that only compete for the cores and memory"
        )


def _chunks(items: Iterable[T], size: int) -> Iterator[list[T]]:
    iterator = iter(items)
    while chunk := list(islice(iterator, size)):
        yield chunk


def _apply_chunk(fn: Callable[[T], R], chunk: Sequence[T]) -> list[tuple[T, R]]:
    """Worker side: ``fn`` over one chunk, keeping each item beside its result."""
    return [(item, fn(item)) for item in chunk]


class Runner:
    """Maps a function over items, in chunks, yielding ``(item, result)`` as chunks finish.
    :meth:`map` is a generator: closing it early cancels the chunks not yet started.

    ``backend`` names the backend and ``workers`` the number of tasks it runs at once.
    """

    backend: str = ""
    workers: int = 1

    def map(
        self, fn: Callable[[T], R], items: Iterable[T], chunksize: int = 1
    ) -> Generator[tuple[T, R], None, None]:  # pragma: no cover - abstract
        raise NotImplementedError

    def session(self, fn: Callable[[Any, T], R], context: Any) -> Session[T, R]:
        """A :class:`Session` running ``fn(context, item)`` per submitted item, with
        ``context`` shipped to each worker once (see the module doc)."""
        raise NotImplementedError  # pragma: no cover - abstract

    def close(self) -> None:
        """Release what this runner holds (nothing by default)."""

    def describe(self) -> str:
        return f"{self.backend}, {self.workers} worker{'s' if self.workers != 1 else ''}"


def _check_chunksize(chunksize: int) -> int:
    check_count("chunksize", chunksize)
    return chunksize


#: Times a task lost with its worker (not one whose function raised) is submitted again.
RETRIES = 2


class Pending(Generic[R]):
    """The answer of one :meth:`Session.submit`: :meth:`result` waits for it."""

    def result(self) -> R:  # pragma: no cover - abstract
        raise NotImplementedError

    def done(self) -> bool:
        """True when :meth:`result` would not wait."""
        return True

    def cancel(self) -> None:
        """Drop the task (its result is not wanted): it does not run if it has not started."""

    def withdraw(self) -> bool:
        """Drop the task only if it surely has not started: True when it was dropped (the
        caller computes the result itself), False when it goes on (:meth:`result` waits)."""
        return False


class Session(Generic[T, R]):
    """``fn(context, item)`` for items submitted one at a time (see the module doc)."""

    def submit(self, item: T) -> Pending[R]:  # pragma: no cover - abstract
        raise NotImplementedError

    def close(self) -> None:
        """Release the context on the workers (nothing by default)."""


class _Lazy(Pending[R]):
    """Computed here, when first asked for: a serial session does no work nobody reads."""

    def __init__(self, fn: Callable[[Any, Any], R], context: Any, item: Any) -> None:
        self._call: tuple[Any, Any, Any] | None = (fn, context, item)
        self._value: Any = None

    def result(self) -> R:
        if self._call is not None:
            fn, context, item = self._call
            self._value = fn(context, item)
            self._call = None
        return self._value

    def done(self) -> bool:
        return self._call is None


class _SerialSession(Session[T, R]):
    def __init__(self, fn: Callable[[Any, T], R], context: Any) -> None:
        self.fn, self.context = fn, context

    def submit(self, item: T) -> Pending[R]:
        return _Lazy(self.fn, self.context, item)


class SerialRunner(Runner):
    """Everything in this process, item by item (``workers=1``)."""

    backend = "local"
    workers = 1

    def map(
        self, fn: Callable[[T], R], items: Iterable[T], chunksize: int = 1
    ) -> Generator[tuple[T, R], None, None]:
        _check_chunksize(chunksize)
        for item in items:
            yield item, fn(item)

    def session(self, fn: Callable[[Any, T], R], context: Any) -> Session[T, R]:
        return _SerialSession(fn, context)


#: Idle seconds after which loky reaps a pool's workers. It is loky's default on purpose: loky
#: keeps ONE executor per process and rebuilds it whenever a caller passes other arguments, so
#: every user of the local pool (the particle semantics, and through it the fixture repair; the
#: rollouts; the benchmarks) asks for it through :func:`local_executor`, with the same
#: arguments.
IDLE_TIMEOUT = 10


#: Seconds between a local worker's checks that the process that started it is alive.
PARENT_POLL = 0.5


def _init_worker(parent: int) -> None:
    """Worker initializer: leave interrupts to the parent, and end with it
    (:func:`_end_with_parent`).

    A Ctrl-C on a terminal reaches the whole process group, workers included. Raised inside a
    task, it would fail that task's chunk and turn the parent's orderly stop (a planning run
    that keeps its plan and the validation rollouts already done) into a traceback; the parent
    decides instead, and cancels the tasks it no longer wants.
    """
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    _end_with_parent(parent)


def _end_with_parent(parent: int) -> None:
    """End this worker as soon as process ``parent`` (the one whose pool it serves) is gone.

    A killed parent cannot stop its pool, and loky's workers would otherwise live on until
    their idle timeout or longer, holding cores. An orphan is adopted by another process, so
    its parent pid changes: a daemon thread polls ``os.getppid()`` (POSIX; a portable test,
    unlike Linux's ``PR_SET_PDEATHSIG``, which fires when the *thread* that started the
    worker ends, and loky starts workers from its own threads too).
    """
    if os.getppid() != parent:
        # Killed while this worker started (loky starts workers as its direct children, and
        # the initializer runs only after the worker's imports, a second or more): the parent
        # is gone already and nothing would end this orphan (docs/design/cli.md, "Orphans at
        # start-up"). A parent
        # that still exists started it through an intermediate process: nothing to watch.
        if not _exists(parent):
            os._exit(1)
        return
    threading.Thread(target=_watch_parent, args=(parent,), name="parent-watch", daemon=True).start()


def _exists(pid: int) -> bool:
    """Whether process ``pid`` exists (signal 0 checks without sending anything)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # pragma: no cover - exists, owned by another user
        return True
    return True


def _watch_parent(parent: int) -> None:
    while os.getppid() == parent:
        time.sleep(PARENT_POLL)
    os._exit(1)  # no cleanup to run: the results have nobody left to go to


def local_executor(workers: int) -> Any:
    """The process's shared loky executor with ``workers`` processes (started on first use,
    reused afterwards; resized, not restarted, when the count changes). Its workers end when
    this process does, however it ends (see :func:`_end_with_parent`). Raises ``ValueError``
    for a count :func:`check_workers` refuses: every local pool starts here."""
    check_workers(workers)
    # lazy: joblib's import is a start-up cost (docs/design/repair.md) that commands which
    # never start a pool must not pay
    from joblib.externals.loky import get_reusable_executor

    return get_reusable_executor(
        max_workers=workers,
        timeout=IDLE_TIMEOUT,
        initializer=_init_worker,
        initargs=(os.getpid(),),
    )


class LocalRunner(Runner):
    """Local worker processes: joblib's loky executor, shared and reused across batches."""

    backend = "local"

    def __init__(self, workers: int) -> None:
        if workers < 2:
            raise ValueError("LocalRunner needs at least 2 workers; use SerialRunner for 1")
        self.workers = workers

    def map(
        self, fn: Callable[[T], R], items: Iterable[T], chunksize: int = 1
    ) -> Generator[tuple[T, R], None, None]:
        from concurrent.futures.process import BrokenProcessPool

        _check_chunksize(chunksize)
        executor = local_executor(self.workers)
        chunks = _chunks(items, chunksize)
        pending: set[Any] = set()

        def submit(chunk: list[T]) -> None:
            pending.add(executor.submit(_apply_chunk, fn, chunk))

        # at most two tasks per worker in flight: results stream back in completion order
        # and an interruption has little queued work to cancel
        for chunk in islice(chunks, 2 * self.workers):
            submit(chunk)
        try:
            while pending:
                done, _ = wait(pending, return_when=FIRST_COMPLETED)
                for future in done:
                    pending.discard(future)
                    try:
                        pairs = future.result()
                    except BrokenProcessPool as error:  # loky's TerminatedWorkerError too
                        raise local_workers_lost(error) from error
                    following = next(chunks, None)
                    if following is not None:
                        submit(following)
                    yield from pairs
        finally:
            # interrupted: drop the queued tasks (running ones finish and are discarded); the
            # pool stays up for the next batch
            for future in pending:
                future.cancel()

    def session(self, fn: Callable[[Any, T], R], context: Any) -> Session[T, R]:
        return _LocalSession(self.workers, fn, context)


#: Worker side of a local session: the contexts this worker has unpickled, by digest, most
#: recently used last (a few, for the runs of one process that share the pool).
_CONTEXTS: OrderedDict[bytes, Any] = OrderedDict()
_CONTEXTS_KEPT = 4


class _ContextMissing:
    """A worker's answer to a task whose context it does not have (sent again with it)."""


def _call_in_context(
    fn: Callable[[Any, Any], Any], digest: bytes, payload: bytes | None, item: Any
) -> Any:
    """Worker side: ``fn(context, item)`` with the context of ``digest``, unpickled from
    ``payload`` the first time this worker sees it."""
    context = _CONTEXTS.get(digest)
    if context is None:
        if payload is None:
            return _ContextMissing()
        context = _CONTEXTS[digest] = pickle.loads(payload)
        while len(_CONTEXTS) > _CONTEXTS_KEPT:
            _CONTEXTS.popitem(last=False)
    else:
        _CONTEXTS.move_to_end(digest)
    return fn(context, item)


class _LocalPending(Pending[R]):
    def __init__(self, session: _LocalSession[Any, R], item: Any) -> None:
        self.session, self.item = session, item
        self.attempts = 0
        self.future = session.send(item, with_context=False)

    def _retry(self, with_context: bool) -> None:
        self.future = self.session.send(self.item, with_context=with_context)

    def done(self) -> bool:
        if not self.future.done():
            return False
        # a worker without the context answered: send again with it, then it is not done
        if not self.future.cancelled() and self.future.exception() is None:
            if isinstance(self.future.result(), _ContextMissing):
                self._retry(with_context=True)
                return False
        return True

    def result(self) -> R:
        from concurrent.futures.process import BrokenProcessPool

        while True:
            try:
                value = self.future.result()
            except BrokenProcessPool as error:  # a worker died (killed, out of memory): the pool is
                self.attempts += 1  # rebuilt by the next local_executor call
                if self.attempts > RETRIES:
                    raise local_workers_lost(error) from error
                self._retry(with_context=True)
                continue
            if isinstance(value, _ContextMissing):
                self._retry(with_context=True)
                continue
            return value

    def cancel(self) -> None:
        self.future.cancel()

    def withdraw(self) -> bool:
        return bool(self.future.cancel())  # False once a worker has it


class _LocalSession(Session[T, R]):
    def __init__(self, workers: int, fn: Callable[[Any, T], R], context: Any) -> None:
        self.workers, self.fn = workers, fn
        self.payload = pickle.dumps(context, protocol=pickle.HIGHEST_PROTOCOL)
        self.digest = hashlib.blake2b(self.payload, digest_size=16).digest()

    def send(self, item: T, *, with_context: bool) -> Any:
        payload = self.payload if with_context else None
        executor = local_executor(self.workers)
        return executor.submit(_call_in_context, self.fn, self.digest, payload, item)

    def submit(self, item: T) -> Pending[R]:
        return _LocalPending(self, item)


class DaskRunner(Runner):
    """A ``dask.distributed`` client: a LocalCluster of its own, or an existing scheduler."""

    backend = "dask"

    def __init__(self, workers: int | None = None, scheduler: str | None = None) -> None:
        distributed = _import_distributed()
        self.scheduler = scheduler
        self._cluster = None
        if scheduler is None:
            n = workers or available_cores()
            self._cluster = distributed.LocalCluster(
                n_workers=n,
                threads_per_worker=1,
                processes=True,
                dashboard_address=None,  # no fixed port: the machine may be shared
                silence_logs=logging.ERROR,
            )
            try:
                self.client = distributed.Client(self._cluster)
            except BaseException:
                self._cluster.close()
                raise
        else:
            try:
                self.client = distributed.Client(scheduler, timeout="10s")
            except (OSError, TimeoutError) as error:
                raise BackendUnavailableError(
                    f"cannot reach the Dask scheduler at {scheduler!r}: {error}"
                ) from None
        info = self.client.scheduler_info()
        threads = sum(w.get("nthreads", 1) for w in info.get("workers", {}).values())
        self.workers = max(1, threads)

    def map(
        self, fn: Callable[[T], R], items: Iterable[T], chunksize: int = 1
    ) -> Generator[tuple[T, R], None, None]:
        from distributed import as_completed  # an optional dependency (see the module doc)

        _check_chunksize(chunksize)
        client = self.client
        # The function carries the problem and the plan: send it to every worker once.
        fn_future = client.scatter(fn, broadcast=True, hash=False)
        chunks = _chunks(items, chunksize)
        in_flight: set[Any] = set()

        def submit(chunk: list[T]) -> Any:
            future = client.submit(_apply_chunk, fn_future, chunk, pure=False)
            in_flight.add(future)
            return future

        # four tasks per worker in flight hide the scheduler's round trip (docs/design/repair.md)
        queue = as_completed([submit(c) for c in islice(chunks, 4 * self.workers)])
        try:
            for future in queue:
                in_flight.discard(future)
                try:
                    pairs = future.result()
                except Exception as error:
                    # an exception of fn itself is raised as it is
                    if not _dask_lost(error):
                        raise
                    raise _dask_workers_lost(error) from error
                following = next(chunks, None)
                if following is not None:
                    queue.add(submit(following))
                yield from pairs
        finally:
            if in_flight:  # interrupted: drop what is queued, keep the cluster
                client.cancel(list(in_flight))

    def session(self, fn: Callable[[Any, T], R], context: Any) -> Session[T, R]:
        return _DaskSession(self.client, fn, context)

    def close(self) -> None:
        self.client.close()
        if self._cluster is not None:
            self._cluster.close()

    def describe(self) -> str:
        where = self.scheduler or "LocalCluster"
        return f"dask ({where}), {self.workers} worker{'s' if self.workers != 1 else ''}"


class _DaskPending(Pending[R]):
    def __init__(self, session: _DaskSession[Any, R], item: Any) -> None:
        self.session, self.item = session, item
        self.attempts = 0
        self.future = session.send(item)

    def done(self) -> bool:
        return bool(self.future.done())

    def result(self) -> R:
        while True:
            try:
                return self.future.result()
            except Exception as error:
                # A worker lost with the task or its context (KilledWorker, a cancelled or
                # lost dependency): send again, re-scattering the context if need be. An
                # exception of fn itself is raised on the first attempt.
                if not _dask_lost(error):
                    raise
                if self.attempts >= RETRIES:
                    raise _dask_workers_lost(error) from error
                self.attempts += 1
                self.session.rescatter()
                self.future = self.session.send(self.item)

    def cancel(self) -> None:
        self.future.cancel()


class _DaskSession(Session[T, R]):
    def __init__(self, client: Any, fn: Callable[[Any, T], R], context: Any) -> None:
        self.client, self.fn, self.context = client, fn, context
        self.rescatter()

    def rescatter(self) -> None:
        # every worker gets the context once (docs/design/planning-performance.md, parallel
        # planning)
        self.context_future = self.client.scatter(self.context, broadcast=True, hash=False)

    def send(self, item: T) -> Any:
        return self.client.submit(self.fn, self.context_future, item, pure=False)

    def submit(self, item: T) -> Pending[R]:
        return _DaskPending(self, item)

    def close(self) -> None:
        self.context_future.release()


def _dask_lost(error: BaseException) -> bool:
    """Whether a Dask task failed because its worker, its data or the scheduler was lost (not
    because its function raised)."""
    from distributed import KilledWorker
    from distributed.client import FutureCancelledError

    return isinstance(error, (KilledWorker, FutureCancelledError, OSError)) or (
        type(error).__name__ in {"CancelledError", "FutureCancelledError"}
    )


def _import_distributed() -> Any:
    try:
        import distributed
    except ImportError as error:
        raise BackendUnavailableError(
            f"the dask backend needs dask.distributed, which is not installed ({error}); "
            f"install it with: {DASK_INSTALL_HINT}"
        ) from None
    return distributed


_RUNNERS: dict[tuple[Any, ...], Runner] = {}
_LOCK = threading.Lock()


def check_runner_options(
    backend: str = "local", workers: int | None = None, scheduler: str | None = None
) -> None:
    """Raise ``ValueError`` for an unknown backend, a worker count that is not a positive
    integer or is more than :func:`max_workers`, or a scheduler address without the dask
    backend; start nothing. A caller that may not need a runner checks its options with this
    first, so that bad options fail alike whether a runner is made or not."""
    if backend not in BACKENDS:
        raise ValueError(f"unknown backend {backend!r}; expected one of {', '.join(BACKENDS)}")
    if workers is not None:
        check_workers(workers)
    if scheduler is not None and backend != "dask":
        raise ValueError("a scheduler address needs the dask backend")


@dataclass(frozen=True)
class RunnerConfig:
    """Where independent work runs (:func:`get_runner`'s arguments as one value): ``"local"``
    with ``workers`` processes (1: in this process; None: every core this process may use), or
    ``"dask"``, a LocalCluster of ``workers`` processes or the cluster at ``scheduler``. Bad
    options raise ``ValueError`` when it is made (:func:`check_runner_options`); nothing starts
    until :meth:`runner` is called."""

    workers: int | None = 1
    backend: str = "local"
    scheduler: str | None = None

    def __post_init__(self) -> None:
        check_runner_options(self.backend, self.workers, self.scheduler)

    def runner(self) -> Runner:
        """The (cached) runner these options name (see :func:`get_runner`)."""
        return get_runner(self.backend, self.workers, self.scheduler)

    def as_options(self) -> dict[str, Any]:
        """The options as :func:`get_runner`'s keyword arguments."""
        return {"workers": self.workers, "backend": self.backend, "scheduler": self.scheduler}


SERIAL = RunnerConfig()
"""One worker, in this process."""


def get_runner(
    backend: str = "local", workers: int | None = None, scheduler: str | None = None
) -> Runner:
    """The runner of a backend, cached per process (pools and clusters live across batches).

    ``workers=None`` means every core this process may use (:func:`available_cores`); for
    ``"dask"`` with a ``scheduler`` address the cluster's own workers are used and ``workers``
    is ignored. Raises ``ValueError`` for the options :func:`check_runner_options` refuses,
    :class:`BackendUnavailableError` when dask is missing or the scheduler cannot be reached.
    """
    check_runner_options(backend, workers, scheduler)
    if backend == "local":
        n = workers or available_cores()
        return SerialRunner() if n == 1 else LocalRunner(n)
    key = ("dask", scheduler) if scheduler else ("dask", workers or available_cores())
    with _LOCK:
        runner = _RUNNERS.get(key)
        if runner is None:
            runner = _RUNNERS[key] = DaskRunner(workers=workers, scheduler=scheduler)
        return runner


def shutdown() -> None:
    """Close every cached Dask client and cluster (registered to run at exit)."""
    with _LOCK:
        runners = list(_RUNNERS.values())
        _RUNNERS.clear()
    for runner in runners:
        try:
            runner.close()
        except Exception:  # pragma: no cover - best effort at exit
            pass


atexit.register(shutdown)


def auto_chunksize(n_items: int, workers: int, *, most: int = 25) -> int:
    """A chunk size giving each worker about four tasks, between 1 and ``most``.

    Several tasks per worker balance the load at the end of a batch; at most ``most`` items per
    task keep results (and progress) flowing and bound what an interrupted batch loses.
    """
    if n_items <= 0:
        return 1
    return max(1, min(most, math.ceil(n_items / (4 * max(1, workers)))))
