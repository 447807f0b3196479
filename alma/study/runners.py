"""Where a study's tasks run: a local process pool or a Dask cluster; rows stream back."""

from __future__ import annotations

import gc
import queue as queue_mod
import sys
from collections.abc import Callable, Sequence
from typing import Any

from alma.study.tasks import _error_text, _init_worker, _solve_task, _solve_task_pooled, _Task


def _run_local(
    tasks: Sequence[_Task], n_workers: int, record: Callable[[dict[str, Any]], None], lost: Callable[[_Task, str], None]
) -> None:
    import multiprocessing as mp
    from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait

    # fork (POSIX) needs no re-import of the caller's __main__; spawn elsewhere.
    methods = mp.get_all_start_methods()
    ctx = mp.get_context("fork" if "fork" in methods and sys.platform != "darwin" else "spawn")
    q = ctx.Queue()
    pool = ProcessPoolExecutor(max_workers=n_workers, mp_context=ctx, initializer=_init_worker, initargs=(q,))

    def drain(block: float | None) -> None:
        try:
            row = q.get(timeout=block) if block else q.get_nowait()
            record(row)
            while True:
                record(q.get_nowait())
        except queue_mod.Empty:
            pass

    futures = {}
    try:
        # The workers are forked at the first submit.  Freezing the collector first leaves every
        # object of the parent out of the children's collections: a child never traverses or
        # frees what it did not make.  (In the test suite a child's full collection once hit a
        # dangling instance dict inherited from the parent and died with SIGSEGV.)
        frozen = ctx.get_start_method() == "fork"
        if frozen:
            gc.freeze()
        try:
            futures = {pool.submit(_solve_task_pooled, t): t for t in tasks}
        finally:
            if frozen:
                gc.unfreeze()
        pending = set(futures)
        while pending:
            drain(0.2)
            finished, pending = wait(pending, timeout=0, return_when=FIRST_COMPLETED)
            for fut in finished:
                task = futures[fut]
                try:
                    rows = fut.result()
                except Exception as exc:  # a worker died (e.g. killed): not a result, retried next run
                    drain(None)
                    lost(task, f"worker failed: {_error_text(exc)}")
                    continue
                for row in rows:  # rows not yet received through the queue
                    record(row)
        drain(None)
    except BaseException:  # Ctrl-C or a failure here: stop the workers, keep what is done
        try:
            drain(None)  # whatever is finished goes to disk
        finally:
            for fut in futures:
                fut.cancel()
            procs = list((getattr(pool, "_processes", None) or {}).values())
            for p in procs:
                if p.is_alive():
                    p.terminate()
            pool.shutdown(wait=False, cancel_futures=True)
        raise
    else:
        pool.shutdown(wait=True)
    finally:
        q.close()


def _run_dask(
    tasks: Sequence[_Task], scheduler: Any, record: Callable[[dict[str, Any]], None], lost: Callable[[_Task, str], None]
) -> None:
    try:
        from distributed import Client, as_completed
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise RuntimeError("--scheduler needs the dask extra: pip install 'alma[dask]'") from exc
    own = not isinstance(scheduler, Client)
    client = Client(scheduler) if own else scheduler
    futures = []
    try:
        futures = [client.submit(_solve_task, t, pure=False) for t in tasks]
        by_future = dict(zip(futures, tasks, strict=True))
        for fut in as_completed(futures):
            task = by_future[fut]
            try:
                rows = fut.result()
            except Exception as exc:  # worker lost etc.: not a result, retried next run
                lost(task, f"dask task failed: {_error_text(exc)}")
                continue
            for row in rows:
                record(row)
    except BaseException:
        try:
            client.cancel(futures)
        finally:
            if own:
                client.close()
        raise
    else:
        if own:
            client.close()
