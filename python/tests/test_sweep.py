"""``shoal.sweep``: plans, run folders and collected tables the same as ``shoal sweep``'s, on a
process pool and on a Dask cluster."""

from __future__ import annotations

import shutil
import subprocess
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import pyarrow as pa
import pyarrow.csv as pacsv
import pytest

import shoal


def write_sweep(folder: Path, tiny: Path, seeds: int = 2) -> Path:
    """A 2 × 2 grid over tiny.ron, short runs."""
    f = folder / "grid.ron"
    f.write_text(
        f"""Sweep(
    scenario: "{tiny}",
    duration: 1.0,
    seed: 11,
    seeds: {seeds},
    axes: [
        (key: "scenario.groups[reef_fish].count", values: [5, 12]),
        (key: "reef_fish.body.limits.max_speed", values: [2.0, 3.5]),
    ],
)
"""
    )
    return f


def cli(shoal_bin: str, *args: object) -> str:
    out = subprocess.run(
        [shoal_bin, *map(str, args)], check=True, capture_output=True, text=True
    )
    return out.stdout


def csv_table(path: Path, like: pa.Table) -> pa.Table:
    """``results.csv`` read with the column types of ``like``."""
    options = pacsv.ConvertOptions(column_types={f.name: f.type for f in like.schema})
    return pacsv.read_csv(path, convert_options=options)


def as_csv_reads(t: pa.Table) -> pa.Table:
    """``t`` as a CSV file gives it back: a null text is an empty field, read as ``""``."""
    return pa.table(
        {
            f.name: pa.compute.fill_null(t[f.name], "") if f.type == pa.string() else t[f.name]
            for f in t.schema
        }
    )


def test_plan_numbers_the_entries_point_by_point_on_common_seeds(tmp_path, tiny):
    entries = shoal.sweep.plan(write_sweep(tmp_path, tiny))
    assert [e.index for e in entries] == list(range(8))
    assert [(e.point, e.replicate) for e in entries][:3] == [(0, 0), (0, 1), (1, 0)]
    # The same seeds at every point: points are compared on common random numbers.
    assert {e.seed for e in entries if e.replicate == 0} == {entries[0].seed}
    assert entries[0].seed != entries[1].seed
    assert entries[3].values == {
        "scenario.groups[reef_fish].count": "5",
        "reef_fish.body.limits.max_speed": "3.5",
    }
    assert entries[3].settings == entries[3].values
    t = shoal.sweep.plan_table(write_sweep(tmp_path, tiny))
    assert t.column_names[:4] == ["index", "point", "replicate", "seed"]
    assert t.num_rows == 8


def test_a_sweep_file_error_is_located(tmp_path, tiny):
    f = write_sweep(tmp_path, tiny)
    f.write_text(f.read_text().replace("seeds: 2", "seeds: 0"))
    with pytest.raises(shoal.LoadError) as e:
        shoal.sweep.plan(f)
    assert f"{f}:5:" in str(e.value) and "seeds" in str(e.value)


def test_run_entry_writes_what_shoal_sweep_run_index_writes(tmp_path, tiny, shoal_bin):
    f = write_sweep(tmp_path, tiny)
    py, sh = tmp_path / "py", tmp_path / "sh"
    shoal.sweep.submit(f, py, _Inline())  # writes the manifest, runs nothing yet
    assert shoal.sweep.pending(f, py) == list(range(8))
    assert shoal.sweep.run_entry(f, 5, py) == "done"
    assert shoal.sweep.run_entry(f, 5, py) == "skipped"
    cli(shoal_bin, "sweep", "run", f, "--out", sh, "--index", 5)
    assert (py / "runs" / "00005" / "result.json").read_bytes() == (
        sh / "runs" / "00005" / "result.json"
    ).read_bytes()
    assert shoal.sweep.pending(f, py) == [0, 1, 2, 3, 4, 6, 7]
    with pytest.raises(RuntimeError, match="not finished"):
        shoal.sweep.collect(py)
    part = shoal.sweep.collect(py, partial=True)
    assert part.num_rows == 1 and part["index"].to_pylist() == [5]
    with pytest.raises(IndexError, match="no run 8"):
        shoal.sweep.run_entry(f, 8, py)


class _Inline:
    """An executor that records what it is given and runs nothing."""

    def __init__(self) -> None:
        self.calls: list = []

    def submit(self, fn, *args):
        self.calls.append((fn, args))
        return None


def test_a_process_pool_collects_the_table_shoal_sweep_collects(tmp_path, tiny, shoal_bin):
    f = write_sweep(tmp_path, tiny)
    sh, py = tmp_path / "sh", tmp_path / "py"
    cli(shoal_bin, "sweep", "run", f, "--out", sh, "-j", "2")
    cli(shoal_bin, "sweep", "collect", sh)
    with ProcessPoolExecutor(max_workers=2) as pool:
        table = shoal.sweep.run(f, py, pool)
    assert table.num_rows == 8
    assert table.equals(shoal.sweep.collect(sh))
    assert as_csv_reads(table).equals(csv_table(sh / "results.csv", table))
    # Interrupted: a run folder lost is the one run again, and the table is the same.
    shutil.rmtree(py / "runs" / "00003")
    assert shoal.sweep.pending(f, py) == [3]
    with ProcessPoolExecutor(max_workers=2) as pool:
        futures = shoal.sweep.submit(f, py, pool)
        assert [fut.result() for fut in futures] == ["done"]
    assert shoal.sweep.collect(py).equals(table)
    shoal.sweep.write_parquet(table, tmp_path / "results.parquet")
    import pyarrow.parquet as pq

    assert pq.read_table(tmp_path / "results.parquet").equals(table)


def test_a_multiprocessing_pool_through_pool_executor(tmp_path, tiny):
    from multiprocessing import get_context

    f = write_sweep(tmp_path, tiny, seeds=1)
    with get_context("spawn").Pool(2) as pool:
        table = shoal.sweep.run(f, tmp_path / "mp", shoal.sweep.PoolExecutor(pool))
    alone = shoal.sweep.run(f, tmp_path / "alone")
    assert table.num_rows == 4
    assert table.equals(alone)


def test_the_issue_sweep_on_a_dask_cluster_matches_shoal_sweep_run(tmp_path, repo, shoal_bin):
    """The 2-axis × 3-seed sweep of sweeps/tiny_grid.ron: `shoal sweep run -j 2` and the package
    on a Dask LocalCluster of 2 worker processes collect identical tables."""
    distributed = pytest.importorskip("dask.distributed")
    f = repo / "sweeps" / "tiny_grid.ron"
    entries = shoal.sweep.plan(f)
    assert len(entries) == 12 and len({e.seed for e in entries}) == 3
    sh, dk = tmp_path / "sh", tmp_path / "dask"
    cli(shoal_bin, "sweep", "run", f, "--out", sh, "-j", "2")
    cli(shoal_bin, "sweep", "collect", sh)
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster, distributed.Client(cluster) as client:
        futures = shoal.sweep.submit(f, dk, client)
        assert len(futures) == 12
        assert set(client.gather(futures)) == {"done"}
    table = shoal.sweep.collect(dk)
    assert table.num_rows == 12
    assert table.equals(shoal.sweep.collect(sh))
    assert as_csv_reads(table).equals(csv_table(sh / "results.csv", table))
    # And `shoal sweep collect` over the Dask run's folder writes the same bytes.
    cli(shoal_bin, "sweep", "collect", dk)
    assert (dk / "results.csv").read_bytes() == (sh / "results.csv").read_bytes()
