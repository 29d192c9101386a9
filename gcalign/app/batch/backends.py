"""Where the chunks of runs execute: one ``concurrent.futures`` executor, a local process
pool or an existing Dask cluster's (:class:`Workers`). The functions sent to workers live
in :mod:`gcalign.app.batch.runs`.
"""

from __future__ import annotations

import os
import re
import signal
import threading
import time
from concurrent.futures import FIRST_COMPLETED, BrokenExecutor, ProcessPoolExecutor, wait
from typing import Any

from gcalign.app.batch.runs import run_chunk, warm_up
from gcalign.errors import GcalignError, ScenarioError, clip

SCHEDULER_TIMEOUT_S = 4.0  # each step of connecting to a Dask scheduler (≤ 15 s in all)
WORKERS_TIMEOUT_S = 4.0  # waiting for a scheduler's first worker


def _watch_parent(parent: int) -> None:  # pragma: no cover - runs in workers
    while True:
        time.sleep(0.5)
        if os.getppid() != parent:
            os._exit(1)  # the batch process died (SIGKILL): do not linger as an orphan


def _die_with_parent(parent: int) -> None:  # pragma: no cover - runs in workers
    """Have the kernel kill this worker when its parent dies (Linux ``PR_SET_PDEATHSIG``).

    The watcher thread (:func:`_watch_parent`) needs the GIL, which a numba kernel holds
    for the whole of a long run: a batch killed with SIGKILL left its pool (three
    processes, 450 MB) computing for nine minutes. The kernel's signal needs nothing from
    the worker. The parent is the process that forked the worker (the batch, or the fork
    server, which exits when the batch does)."""
    import ctypes
    import ctypes.util

    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6", use_errno=True)
        libc.prctl(1, signal.SIGKILL, 0, 0, 0)  # PR_SET_PDEATHSIG = 1
    except (OSError, AttributeError):  # not Linux: the watcher thread only
        return
    if os.getppid() != parent:  # the parent died before the request took effect
        os._exit(1)


def _init_worker(command: str) -> None:  # pragma: no cover - runs in workers
    """Process-pool initializer: Ctrl-C is the parent's business, SIGTERM kills; exit with
    the parent; load the JIT cache once."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    # A forked worker inherits the command's SIGTERM handler (which raises, so that the
    # command removes its temporary files): a worker that the pool terminates must die,
    # not send the exception back through a queue nobody reads any more (a hang at exit).
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    # Forked with SIGTERM blocked (local_workers): one sent before this point was
    # held, and is delivered now, with the default action.
    signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGTERM})
    parent = os.getppid()
    _die_with_parent(parent)
    threading.Thread(target=_watch_parent, args=(parent,), daemon=True).start()
    warm_up(command)


class WorkerLost(Exception):
    """The process running a chunk died (killed, crashed, out of memory)."""


class Workers:
    """Where a batch's chunks run: one ``concurrent.futures.Executor`` — a local process pool
    (:func:`local_workers`) or Dask's ``Client.get_executor()`` (:func:`dask_workers`) —
    behind the one code path of the engine. A chunk whose worker died is :class:`WorkerLost`
    (the engine retries its runs alone); a local pool that a dying worker broke is replaced
    at the next submit; `check` says whether the executor can still run anything (a Dask
    client that lost its scheduler cannot: one line, the finished runs kept)."""

    def __init__(self, executor, workers: int, description: str, *, renew=None,
                 check=None, stop=None, start_method: str | None = None):
        self.executor = executor
        self.workers = workers
        self.description = description
        self.start_method = start_method
        self._renew = renew  # a new executor in place of a broken one
        self._check = check or (lambda: None)
        self._stop = stop  # (executor, cancel) -> None: shut it down

    def submit(self, chunk):
        self._check()
        try:
            return self.executor.submit(run_chunk, chunk)
        except BrokenExecutor:  # a local worker died and broke its pool: start a new one
            if self._renew is None:
                raise
            self._stop(self.executor, True)
            self.executor = self._renew()
            return self.executor.submit(run_chunk, chunk)

    def wait(self, futures, timeout: float):
        done = wait(futures, timeout=timeout, return_when=FIRST_COMPLETED)[0]
        if not done:
            self._check()
        return done

    def result(self, fut) -> list[dict]:
        try:
            return fut.result()
        except Exception as err:  # BrokenProcessPool, KilledWorker, CancelledError, ...
            self._check()
            raise WorkerLost(f"{type(err).__name__}: {err}" if str(err) else
                             f"a worker process died ({type(err).__name__})") from None

    def close(self, cancel: bool = False) -> None:
        self._stop(self.executor, cancel)


def local_workers(workers: int, command: str) -> Workers:
    """A ``ProcessPoolExecutor`` of `workers` processes, each warming the JIT cache once
    (initializer).

    Start method: ``fork`` when this process has no other thread (the workers then start
    with every module already imported: no interpreter start, no re-import), else the fork
    server (forking a multi-threaded process can deadlock the child). The processes are
    started here, before the caller starts a progress-bar thread.
    """
    import multiprocessing as mp

    # Warm the kernels here, once: forked workers inherit them and start in milliseconds
    # instead of each loading the JIT cache again (about 0.6 s apiece).
    warm_up(command)
    methods = mp.get_all_start_methods()
    ctx: Any
    if "fork" in methods and threading.active_count() == 1:
        ctx = mp.get_context("fork")
    elif "forkserver" in methods:
        ctx = mp.get_context("forkserver")
        # The fork server imports the engine (numpy, numba, pipelines) once; every
        # worker forked from it starts with those modules loaded.
        ctx.set_forkserver_preload(["gcalign.app.batch", "gcalign.app.align.run"])
    else:
        ctx = mp.get_context("spawn")

    def new_pool() -> ProcessPoolExecutor:
        pool = ProcessPoolExecutor(max_workers=workers, mp_context=ctx,
                                   initializer=_init_worker, initargs=(command,))
        if ctx.get_start_method() == "fork":
            # Forks every worker now (all at once for fork), with SIGTERM blocked: until its
            # initializer runs, a worker has the command's handler, under which a terminate
            # raised inside it and left it alive. The parent receives a held one on unblock.
            blocked = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGTERM})
            try:
                first = pool.submit(os.getpid)
            finally:
                signal.pthread_sigmask(signal.SIG_SETMASK, blocked)
            first.result()
        return pool

    def stop(pool: ProcessPoolExecutor, cancel: bool) -> None:
        if not cancel:
            pool.shutdown(wait=True)
            return
        procs = list((getattr(pool, "_processes", None) or {}).values())
        pool.shutdown(wait=False, cancel_futures=True)
        for p in procs:  # do not wait for chunks in flight after Ctrl-C
            if p.is_alive():
                p.terminate()

    return Workers(new_pool(), workers, f"local pool, {workers} worker(s)", renew=new_pool,
                   stop=stop, start_method=ctx.get_start_method())


def _probe(address: str, timeout: float) -> None:
    """Ask `address` for its identity, all of it within `timeout` s: a listener that is not a
    Dask scheduler (a plain TCP or HTTP server) accepts the connection and never answers
    what ``distributed.Client`` waits for, without a time limit."""
    import asyncio

    from distributed.comm import connect

    async def ask() -> dict:
        comm = await connect(address, timeout=timeout)
        try:
            await comm.write({"op": "identity", "reply": True})
            return await comm.read()
        finally:
            comm.abort()

    reply = asyncio.run(asyncio.wait_for(ask(), timeout))
    if not isinstance(reply, dict) or reply.get("type") != "Scheduler":
        raise OSError(f"not a Dask scheduler (it answered {str(reply)[:60]!r})")


#: Dask's network schemes (``distributed.comm``); ``inproc`` is this process, not a cluster
SCHEMES = ("tcp", "tls", "ws", "wss", "ucx")
_HOST_LABEL = re.compile(r"^(?!-)[A-Za-z0-9-]{1,63}(?<!-)$")


def check_address(address: str) -> str:
    """`address` as a Dask scheduler address ``SCHEME://HOST:PORT`` (SCHEME one of
    :data:`SCHEMES`, ``tcp`` when omitted; HOST a name, an IPv4 address or a bracketed IPv6
    one; PORT 1..65535): ScenarioError naming ``--scheduler`` at once, instead of a failed
    connection seconds later (port 0, 99999, no port, ``http://``, an unclosed bracket, a
    5000-character host), and for an empty one, which ran locally in silence."""
    import ipaddress

    text = str(address).strip()
    shown = clip(text, 60)

    def bad(why: str) -> ScenarioError:
        return ScenarioError(f"--scheduler: {shown!r} {why}; give tcp://HOST:PORT (e.g. "
                             "tcp://10.0.0.5:8786), or leave the option out to run locally")

    if not text:
        raise bad("is empty")
    scheme, sep, rest = text.partition("://")
    if not sep:
        scheme, rest = "tcp", text
    if scheme not in SCHEMES:
        raise bad(f"has the scheme {scheme!r}; Dask schedulers speak {', '.join(SCHEMES)}")
    if rest.startswith("["):
        host, bracket, tail = rest[1:].partition("]")
        if not bracket:
            raise bad("opens an IPv6 bracket and never closes it")
        try:
            ipaddress.IPv6Address(host)
        except ValueError:
            raise bad(f"has {host!r} in brackets, not an IPv6 address") from None
        if not tail.startswith(":"):
            raise bad("has no port after the IPv6 address")
        port = tail[1:]
    else:
        host, colon, port = rest.rpartition(":")
        if not colon:
            raise bad("has no port")
        if ":" in host:
            raise bad("has an IPv6 address without brackets ([::1]:8786)")
        if len(host) > 253 or not all(_HOST_LABEL.match(x) for x in host.split(".")):
            raise bad("does not name a host (letters, digits, '-' and '.', at most 253 "
                      "characters)")
    if not (port.isdigit() and 1 <= int(port) <= 65535):
        raise bad(f"has the port {port[:12]!r}; a port is 1..65535")
    return text if sep else f"tcp://{text}"


def dask_client(address: str, timeout: float = SCHEDULER_TIMEOUT_S,
                workers_timeout: float = WORKERS_TIMEOUT_S):
    """A ``distributed.Client`` connected to `address` with at least one worker; GcalignError
    (one line) if Dask is missing, `address` is not a scheduler that answers within
    `timeout` seconds, or no worker joins within `workers_timeout` s. The whole attempt
    takes at most ``2 * timeout + workers_timeout`` (15 s by default)."""
    try:
        import distributed
    except ImportError:
        raise GcalignError('--scheduler needs Dask distributed, which is not installed: '
                           'pip install -e ".[dask]"') from None

    def fail(err: BaseException) -> GcalignError:
        msg = str(err).strip().splitlines()[0] if str(err).strip() else type(err).__name__
        return GcalignError(f"cannot reach the Dask scheduler at {address} "
                            f"(waited {timeout:g} s): {msg[:120]}")

    _quiet_dask()
    try:
        _probe(address, timeout)
    except Exception as err:  # OSError, TimeoutError, ValueError (bad address), ...
        raise fail(err) from None
    try:
        client = distributed.Client(address, timeout=timeout, set_as_default=False)
    except Exception as err:
        raise fail(err) from None
    try:
        client.wait_for_workers(1, timeout=workers_timeout)
    except Exception:
        _close(client)
        raise GcalignError(f"the Dask scheduler at {address} has no workers (waited "
                           f"{workers_timeout:g} s); start some with 'dask worker {address}'"
                           ) from None
    return client


def _quiet_dask() -> None:
    """Silence Dask's own loggers in this process: when the scheduler dies, the client logs
    "distributed.client - ERROR - Failed to reconnect ..." on stderr before our one error
    line says the same (and what to do: --resume); a gather in flight then also ends in
    tornado's log of the failed callback, with its traceback ("tornado.application")."""
    import logging

    names = ["distributed", "tornado.application", *(
        n for n in logging.root.manager.loggerDict if n.startswith("distributed."))]
    for name in names:
        logging.getLogger(name).setLevel(logging.CRITICAL + 1)


def _close(client) -> None:
    try:
        client.close(timeout=SCHEDULER_TIMEOUT_S)
    except Exception:  # noqa: BLE001 - closing a broken connection
        pass


def dask_workers(address: str, command: str, timeout: float = SCHEDULER_TIMEOUT_S) -> Workers:
    """The workers of an existing Dask distributed cluster, through ``client.get_executor``."""
    client = dask_client(address, timeout)
    nthreads = client.nthreads()
    try:  # load the JIT cache on every worker, in parallel; checks gcalign is there
        client.run(warm_up, command)
    except Exception as err:
        _close(client)
        raise GcalignError(f"the Dask workers of {address} cannot run gcalign "
                           f"({type(err).__name__}: {err}); install gcalign where the "
                           "workers run") from None

    def check() -> None:
        if client.status not in ("running", "connecting"):
            raise GcalignError(f"lost the Dask scheduler at {address} (client "
                               f"{client.status}); the finished runs are kept: rerun "
                               "with --resume")

    def stop(executor, cancel: bool) -> None:
        _close(client)  # its futures released: the scheduler drops what is in flight

    return Workers(client.get_executor(pure=False), max(1, sum(nthreads.values())),
                   f"Dask scheduler {address}, {len(nthreads)} worker(s)", check=check,
                   stop=stop)

