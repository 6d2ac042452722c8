"""Run shoal scenarios and parameter sweeps from Python.

``shoal.run`` runs a scenario in this process, with keys of the scenario and species files
overridden, and returns its trajectories, events and food as ``pyarrow`` tables (``to_pandas()``
for DataFrames) and its summary and run health as dicts; nothing is written to disk.
``shoal.sweep`` plans, runs and collects sweep files, locally or on any
``concurrent.futures``-style executor (a process pool, a Dask ``Client``, Ray's pool).

See ``docs/python.md`` in the repository.
"""

from __future__ import annotations

import json
import math
import os
from typing import (
    TYPE_CHECKING,
    Any,
    Dict,
    Iterable,
    List,
    Mapping,
    NamedTuple,
    Optional,
    Tuple,
    Union,
)

import pyarrow as pa

from . import _native
from ._native import LoadError
from ._tables import table as _table

if TYPE_CHECKING:  # pragma: no cover
    import pandas

__all__ = [
    "LoadError",
    "RunResult",
    "Frames",
    "run",
    "ron",
    "settings",
    "engine_version",
    "sweep",
]

#: A path to a file: ``str`` or ``os.PathLike``.
PathLike = Union[str, "os.PathLike[str]"]

#: Keys to override: ``{"sardine.vision.radius": 12.0, ...}``, or ``["KEY=VALUE", ...]`` with
#: each value written as RON text.
Settings = Union[Mapping[str, Any], Iterable[str]]


def engine_version() -> str:
    """The version of the engine this package was built from."""
    return _native.engine_version()


def ron(value: Any) -> str:
    """``value`` written as RON text, the way a setting's value is given to the engine.

    ``bool``, ``int`` and ``float`` are written as numbers (a float always with a ``.`` or an
    exponent, so that RON reads a float), a ``list`` as ``[...]``, a ``tuple`` as ``(...)``, a
    ``dict`` as a struct ``(key: value, ...)`` and ``None`` as ``None``. A ``str`` is RON text
    already, written as it would be in the file: ``"Random"`` is an enum variant, ``'"reef"'``
    a quoted string.
    """
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if not math.isfinite(value):
            raise ValueError(f"{value!r} cannot be a setting's value (RON has no such number)")
        text = repr(value)
        return text if any(c in text for c in ".eE") else text + ".0"
    if isinstance(value, str):
        return value
    if value is None:
        return "None"
    if isinstance(value, list):
        return "[" + ", ".join(ron(v) for v in value) + "]"
    if isinstance(value, tuple):
        return "(" + ", ".join(ron(v) for v in value) + ")"
    if isinstance(value, dict):
        return "(" + ", ".join(f"{k}: {ron(v)}" for k, v in value.items()) + ")"
    # numpy scalars and other numbers.
    if hasattr(value, "item"):
        return ron(value.item())
    raise TypeError(f"cannot write a {type(value).__name__} as a setting's value: {value!r}")


def settings(set: Optional[Settings]) -> List[Tuple[str, str]]:
    """``set`` as ``(key, RON text)`` pairs, in the order given.

    A mapping's values go through :func:`ron`; a string ``"KEY=VALUE"`` is split at its first
    ``=`` and its value kept as written.
    """
    if set is None:
        return []
    if isinstance(set, Mapping):
        return [(str(k), ron(v)) for k, v in set.items()]
    if isinstance(set, str):
        set = [set]
    out = []
    for s in set:
        key, eq, value = str(s).partition("=")
        if not eq or not key.strip():
            raise ValueError(f"a setting is KEY=VALUE, got {s!r}")
        out.append((key.strip(), value.strip()))
    return out


class Frames(NamedTuple):
    """A run's tables as pandas DataFrames (``RunResult.to_pandas``)."""

    trajectories: "pandas.DataFrame"
    events: "pandas.DataFrame"
    food: "pandas.DataFrame"


class RunResult:
    """What :func:`run` returns: a finished run's tables, summary and health.

    Attributes:
        trajectories: one row per agent per recorded tick, the columns of ``trajectories.csv``
            (``species`` and ``behavior`` are dictionary-encoded: categories in pandas).
        events: one row per event, the keys of ``events.jsonl`` as columns (null where an event
            has no such key); a message's sender is in ``sender`` and a named event's payload is
            its JSON text.
        food: one row per food item per recorded tick, the columns of ``food.csv``.
        summary: the summary ``manifest.json`` holds (alive per species, counters, behavior time
            shares, expectations, the health headline, ``ticks_per_second``).
        health: the run-health report of ``health.json``.
    """

    trajectories: pa.Table
    events: pa.Table
    food: pa.Table
    summary: Dict[str, Any]
    health: Dict[str, Any]

    def __init__(
        self,
        trajectories: pa.Table,
        events: pa.Table,
        food: pa.Table,
        summary: Dict[str, Any],
        health: Dict[str, Any],
    ) -> None:
        self.trajectories = trajectories
        self.events = events
        self.food = food
        self.summary = summary
        self.health = health

    @property
    def expectations(self) -> List[Dict[str, Any]]:
        """The scenario's expectations: ``{"expected", "passed", "observed"}`` each."""
        return list(self.summary.get("expectations", []))

    def to_pandas(self) -> Frames:
        """The three tables as pandas DataFrames (needs ``pandas``)."""
        return Frames(
            self.trajectories.to_pandas(),
            self.events.to_pandas(),
            self.food.to_pandas(),
        )

    def __repr__(self) -> str:
        return (
            f"RunResult({self.summary.get('ticks')} ticks, "
            f"{self.trajectories.num_rows} trajectory rows, {self.events.num_rows} events, "
            f"alive={self.summary.get('alive')})"
        )


def run(
    scenario: PathLike,
    *,
    seed: Optional[int] = None,
    duration: Optional[float] = None,
    set: Optional[Settings] = None,
    record_interval: Optional[int] = None,
    threads: Optional[int] = None,
) -> RunResult:
    """Runs ``scenario`` to its end in this process and returns its tables; writes no file.

    Args:
        scenario: the scenario file (RON).
        seed: the run's seed (default: the scenario's).
        duration: simulated seconds (default: the scenario's).
        set: keys of the scenario or its species files to override, as ``shoal run --set``
            takes them: ``{"sardine.<key>": 12.0, "scenario.groups[0].count": 50}`` (values
            written as RON by :func:`ron`) or ``["KEY=VALUE", ...]``.
        record_interval: record agent states every this many ticks (default: the scenario's).
        threads: worker threads of this run (default: all cores); give ``1`` when many runs go
            on at once.

    Raises:
        LoadError: the scenario, a species or a setting did not load; the message holds the
            located diagnostics (``file:line:col``), as ``shoal run`` prints them.

    The interpreter is released while the engine steps, so runs in several Python threads go
    on in parallel. The same inputs and seed give the same tables, whatever ``threads``.
    """
    out = _native.run_scenario(
        os.fspath(scenario),
        seed=seed,
        duration=duration,
        set=settings(set),
        record_interval=record_interval,
        threads=threads,
    )
    return RunResult(
        trajectories=_table(out["trajectories"]),
        events=_table(out["events"]),
        food=_table(out["food"]),
        summary=json.loads(out["summary"]),
        health=json.loads(out["health"]),
    )


from . import sweep  # noqa: E402  (uses the names above)
