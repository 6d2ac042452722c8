"""Sweeps from Python: plan a sweep file, run its entries, collect the results.

The functions here do what ``shoal sweep plan / run / collect`` do, through the same engine code:
:func:`run_entry` writes the same run folder as ``shoal sweep run --index``, and :func:`collect`
reads the same table ``shoal sweep collect`` writes as ``results.csv``. :func:`submit` hands every
unfinished entry to any ``concurrent.futures``-style executor (an object whose
``submit(fn, *args)`` returns a future): a ``ProcessPoolExecutor``, a Dask ``Client``, or a
pool with ``apply_async`` (``multiprocessing.Pool``, Ray's ``ray.util.multiprocessing.Pool``)
through :class:`PoolExecutor`. What is
submitted is a module-level function of this module with plain arguments, so it pickles; every
worker needs this package installed and the sweep's files at the same paths.

A run folder is written atomically (``OUT/runs/NNNNN/`` appears whole or not at all), so
submitting again after an interruption runs only what did not finish, and the collected table is
the same whatever the executor, the order or the number of workers.
"""

from __future__ import annotations

import os
from typing import Any, Dict, List, NamedTuple, Optional, Protocol, Sequence

import pyarrow as pa

from . import _native
from ._tables import table as _table

__all__ = [
    "Entry",
    "Executor",
    "PoolExecutor",
    "plan",
    "plan_table",
    "pending",
    "run_entry",
    "collect",
    "write_parquet",
    "submit",
    "run",
]


class Entry(NamedTuple):
    """One planned run of a sweep."""

    #: Its number (``shoal sweep run --index``), from 0: ``point * seeds + replicate``.
    index: int
    #: The point (combination of axis values) it runs.
    point: int
    #: Which of the point's seeds it is, from 0.
    replicate: int
    #: Its seed, derived from the sweep's seed and the replicate number (the same for every
    #: point: points are compared on common random numbers).
    seed: int
    #: The settings it runs with: key → value as RON text.
    settings: Dict[str, str]
    #: The sweep's axis values of this entry: key → value as RON text.
    values: Dict[str, str]


class Executor(Protocol):
    """What :func:`submit` needs of an executor: ``submit(fn, *args)`` returning a future."""

    def submit(self, fn: Any, *args: Any) -> Any:  # pragma: no cover
        ...


class PoolExecutor:
    """An executor over a pool with ``apply_async(fn, args)``: ``multiprocessing.Pool``, or
    Ray's ``ray.util.multiprocessing.Pool``, which runs the calls on a Ray cluster.

    >>> from multiprocessing import Pool
    >>> with Pool(2) as pool:
    ...     table = shoal.sweep.run("sweeps/tiny_grid.ron", "out", PoolExecutor(pool))
    """

    def __init__(self, pool: Any) -> None:
        self.pool = pool

    def submit(self, fn: Any, *args: Any) -> Any:
        """Starts ``fn(*args)`` on the pool; returns its ``AsyncResult`` (``get()`` waits)."""
        return self.pool.apply_async(fn, args)


def _path(p: "os.PathLike[str] | str") -> str:
    # Workers may start in another folder: hand them absolute paths.
    return os.path.abspath(os.fspath(p))


def plan(path: "os.PathLike[str] | str") -> List[Entry]:
    """The numbered runs the sweep file ``path`` expands into (``shoal sweep plan``).

    Raises:
        shoal.LoadError: the sweep file, its scenario or a setting did not load (located
            diagnostics).
    """
    return [
        Entry(
            e["index"],
            e["point"],
            e["replicate"],
            e["seed"],
            dict(e["settings"]),
            dict(e["values"]),
        )
        for e in _native.sweep_plan(_path(path))
    ]


def plan_table(path: "os.PathLike[str] | str") -> pa.Table:
    """:func:`plan` as a table: ``index``, ``point``, ``replicate``, ``seed``, then one column
    per axis (its values as RON text)."""
    entries = plan(path)
    keys: List[str] = []
    for e in entries:
        keys.extend(k for k in e.values if k not in keys)
    columns: Dict[str, Any] = {
        "index": pa.array([e.index for e in entries], pa.uint64()),
        "point": pa.array([e.point for e in entries], pa.uint64()),
        "replicate": pa.array([e.replicate for e in entries], pa.uint32()),
        "seed": pa.array([e.seed for e in entries], pa.uint64()),
    }
    for k in keys:
        columns[k] = pa.array([e.values.get(k) for e in entries], pa.string())
    return pa.table(columns)


def pending(path: "os.PathLike[str] | str", out: "os.PathLike[str] | str") -> List[int]:
    """The indices of the sweep's entries with no finished run folder under ``out`` yet."""
    return list(_native.sweep_pending(_path(path), _path(out)))


def run_entry(
    path: "os.PathLike[str] | str",
    index: int,
    out: "os.PathLike[str] | str",
    threads: int = 1,
) -> str:
    """Runs entry ``index`` of the sweep into ``out`` (``shoal sweep run --index``): its run
    folder ``out/runs/NNNNN/``, written atomically; an entry already finished is skipped.

    Returns what became of it: ``"done"``, ``"skipped"`` (finished before) or ``"failed"`` (its
    load or script error is recorded in its folder and its row of the results says so).
    """
    return _native.sweep_run_entry(_path(path), int(index), _path(out), int(threads))


def collect(out: "os.PathLike[str] | str", *, partial: bool = False) -> pa.Table:
    """Every finished run under ``out`` as one table, in index order: the content of the
    ``results.csv`` that ``shoal sweep collect`` writes.

    Raises:
        RuntimeError: runs are not finished yet (their indices are named), unless ``partial``.
    """
    return _table(_native.sweep_collect(_path(out), bool(partial)))


def write_parquet(table: pa.Table, path: "os.PathLike[str] | str") -> None:
    """Writes a collected table as Parquet (pandas, polars and DuckDB read it directly)."""
    import pyarrow.parquet as pq

    pq.write_table(table, os.fspath(path))


def submit(
    path: "os.PathLike[str] | str",
    out: "os.PathLike[str] | str",
    executor: Executor,
    *,
    threads: int = 1,
) -> List[Any]:
    """Submits every unfinished entry of the sweep to ``executor``, one call of
    :func:`run_entry` each, and returns the futures (in index order).

    ``threads`` is each run's worker threads: runs, not threads, are the unit of a sweep, so
    keep 1 unless the executor has fewer workers than cores.
    """
    path, out = _path(path), _path(out)
    # The manifest is written here, once, before any worker writes a run folder beside it.
    _native.sweep_prepare(path, out)
    return [executor.submit(run_entry, path, i, out, threads) for i in pending(path, out)]


def _wait(futures: Sequence[Any]) -> List[Any]:
    """The futures' results: ``concurrent.futures`` and Dask futures have ``result()``, Ray's
    ``AsyncResult`` has ``get()``."""
    results = []
    for f in futures:
        if hasattr(f, "result"):
            results.append(f.result())
        elif hasattr(f, "get"):
            results.append(f.get())
        else:  # pragma: no cover
            raise TypeError(f"cannot wait for a {type(f).__name__}")
    return results


def run(
    path: "os.PathLike[str] | str",
    out: "os.PathLike[str] | str",
    executor: Optional[Executor] = None,
    *,
    threads: int = 1,
) -> pa.Table:
    """Runs every unfinished entry of the sweep (on ``executor``, or one after the other in this
    process), waits for them and returns :func:`collect`'s table.

    Raises:
        RuntimeError: a run could not be written (a run whose scenario or script failed is not
            an error: its row says so).
    """
    if executor is None:
        _native.sweep_prepare(_path(path), _path(out))
        for i in pending(path, out):
            run_entry(path, i, out, threads)
    else:
        _wait(submit(path, out, executor, threads=threads))
    return collect(out)
