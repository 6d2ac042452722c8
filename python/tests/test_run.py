"""``shoal.run``: tables like the run folder's files, overrides, errors, determinism, the GIL."""

from __future__ import annotations

import json
import subprocess
import threading
import time
from pathlib import Path

import pyarrow as pa
import pyarrow.csv as pacsv
import pytest

import shoal

TRAJECTORY_COLUMNS = (
    "tick,time,id,species,x,y,z,fx,fy,fz,speed,behavior,stack_depth,"
    "hunger,libido,fear,swim_phase,tail_bend"
).split(",")


def test_tables_have_the_run_folder_columns_and_one_row_per_agent_and_recorded_tick(tiny):
    r = shoal.run(tiny, seed=2, duration=2.0, record_interval=5)
    t = r.trajectories
    assert t.column_names == TRAJECTORY_COLUMNS
    assert r.food.column_names == ["tick", "id", "x", "y", "z"]
    assert r.events.column_names[:3] == ["tick", "time", "kind"]
    # 2 s at dt 0.05 = 40 ticks, recorded at 0, 5, ..., 40; nobody dies that early.
    assert r.summary["ticks"] == 40
    ticks = t.column("tick").to_pylist()
    assert sorted(set(ticks)) == list(range(0, 41, 5))
    assert t.num_rows == 9 * 41
    assert r.events.filter(pa.compute.equal(r.events["kind"], "spawn")).num_rows == 41
    assert r.summary["alive"] == {"reef_fish": 40, "shark": 1}
    assert set(r.health) >= {"format", "species"}
    assert isinstance(r.expectations, list)


def test_tables_hold_what_shoal_run_writes_to_its_run_folder(tiny, shoal_bin, tmp_path):
    out = tmp_path / "run"
    subprocess.run(
        [shoal_bin, "run", str(tiny), "--seed", "4", "--duration", "3", "--out", str(out), "-q"],
        check=True,
        capture_output=True,
    )
    r = shoal.run(tiny, seed=4, duration=3.0)
    # The CSV's shortest round-trip floats read back as the same float32 bits.
    types = {f.name: f.type for f in r.trajectories.schema}
    types["species"] = types["behavior"] = pa.string()
    csv = pacsv.read_csv(
        out / "trajectories.csv", convert_options=pacsv.ConvertOptions(column_types=types)
    )
    ours = r.trajectories.cast(csv.schema)
    assert ours.num_rows == csv.num_rows > 0
    assert ours.equals(csv)
    food = pacsv.read_csv(
        out / "food.csv",
        convert_options=pacsv.ConvertOptions(column_types={f.name: f.type for f in r.food.schema}),
    )
    assert r.food.equals(food)
    lines = [json.loads(line) for line in (out / "events.jsonl").read_text().splitlines()]
    rows = r.events.to_pylist()
    assert len(rows) == len(lines) > 0
    for row, line in zip(rows, lines):
        if isinstance(line.get("from"), int):
            line["sender"] = line.pop("from")
        if "payload" in line:
            # A named event's payload is its JSON text in the table.
            row["payload"] = json.loads(row["payload"])
        got = {k: v for k, v in row.items() if v is not None}
        want = {k: v for k, v in line.items() if v is not None}
        if "radius" in want:
            assert got.pop("radius") == pytest.approx(want.pop("radius"), rel=1e-6)
        assert got == want
    manifest = json.loads((out / "manifest.json").read_text())
    for k in ("alive", "food_eaten", "catches", "matings", "transitions", "behavior_shares"):
        assert r.summary[k] == manifest["summary"][k], k


def test_the_same_seed_gives_the_same_tables_whatever_the_threads(tiny):
    a = shoal.run(tiny, seed=7, duration=3.0, threads=1)
    b = shoal.run(tiny, seed=7, duration=3.0, threads=2)
    assert a.trajectories.equals(b.trajectories)
    assert a.events.equals(b.events)
    assert a.food.equals(b.food)
    c = shoal.run(tiny, seed=8, duration=3.0, threads=1)
    assert not a.trajectories.equals(c.trajectories)


def test_a_load_error_raises_with_the_located_diagnostic(tmp_path, repo):
    bad = tmp_path / "bad.ron"
    text = (repo / "scenarios" / "tiny.ron").read_text()
    text = text.replace("dt: 0.05,", "dt: 0.05,\n    dtt: 1.0,")
    # Where the species are: the scenario names them relative to its own folder.
    text = text.replace("Scenario(", f'Scenario(\n    behaviors: Some("{repo / "behaviors"}"),', 1)
    bad.write_text(text)
    line = text.splitlines().index("    dtt: 1.0,") + 1
    with pytest.raises(shoal.LoadError) as e:
        shoal.run(bad)
    assert f"{bad}:{line}:5" in str(e.value)
    assert "dtt" in str(e.value)
    assert isinstance(e.value, ValueError)


def test_a_missing_file_is_a_load_error_naming_it(tmp_path):
    with pytest.raises(shoal.LoadError, match="nope.ron"):
        shoal.run(tmp_path / "nope.ron")


def test_the_interpreter_is_released_while_the_engine_steps(tiny):
    done = threading.Event()
    span = {}

    def work():
        span["start"] = time.perf_counter()
        out = shoal._native.run_scenario(str(tiny), seed=1, duration=60.0, threads=1)
        span["end"] = time.perf_counter()
        span["ticks"] = json.loads(out["summary"])["ticks"]
        done.set()

    t = threading.Thread(target=work)
    t.start()
    # This thread keeps waking up while the engine runs; with the interpreter held by the run it
    # could not wake up at all until the run ended.
    wakes = []
    while not done.is_set():
        wakes.append(time.perf_counter())
        time.sleep(0.001)
    t.join()
    assert span["ticks"] == 1200
    elapsed = span["end"] - span["start"]
    during = sum(1 for w in wakes if span["start"] < w < span["end"])
    assert elapsed > 0.05, "the run was too quick to tell"
    # Each wake-up takes a little over a millisecond: at least a quarter of them happened.
    assert during >= elapsed / 0.0011 / 4, f"this thread woke {during} times in {elapsed:.2f} s"


def test_ron_writes_python_values_as_ron_text():
    assert shoal.ron(3) == "3"
    assert shoal.ron(2.0) == "2.0"
    assert shoal.ron(1e-7) == "1e-07"
    assert shoal.ron(True) == "true"
    assert shoal.ron([1, 2.5]) == "[1, 2.5]"
    assert shoal.ron((1.0, 2.0, 3.0)) == "(1.0, 2.0, 3.0)"
    assert shoal.ron({"min": (0, 1)}) == "(min: (0, 1))"
    assert shoal.ron("Random") == "Random"
    assert shoal.settings(["a.b=1", "c = (1, 2)"]) == [("a.b", "1"), ("c", "(1, 2)")]
    with pytest.raises(ValueError, match="KEY=VALUE"):
        shoal.settings(["nokey"])
    with pytest.raises(ValueError):
        shoal.ron(float("nan"))


def test_overrides_change_the_run(tiny):
    base = shoal.run(tiny, seed=2, duration=1.0)
    more = shoal.run(tiny, seed=2, duration=1.0, set={"scenario.groups[reef_fish].count": 10})

    def per_tick(r: shoal.RunResult) -> int:
        return r.trajectories.filter(pa.compute.equal(r.trajectories["tick"], 0)).num_rows

    assert per_tick(base) == 41
    assert per_tick(more) == 11
    assert more.summary["alive"]["reef_fish"] == 10
    longer = shoal.run(tiny, seed=2, set=["scenario.duration=1.5"])
    assert longer.summary["ticks"] == 30
    slow = shoal.run(tiny, seed=2, duration=1.0, set={"reef_fish.body.limits.max_speed": 0.5})

    def fastest_fish(r: shoal.RunResult) -> float:
        t = r.trajectories
        fish = t.filter(pa.compute.equal(t["species"].cast(pa.string()), "reef_fish"))
        return pa.compute.max(fish["speed"]).as_py()

    assert fastest_fish(slow) <= 0.5 + 1e-6
    assert fastest_fish(base) > 0.5


def test_an_unknown_key_is_a_located_error_with_a_suggestion(tiny):
    with pytest.raises(shoal.LoadError) as e:
        shoal.run(tiny, set={"reef_fish.senses.vision_radus": 3.0})
    message = str(e.value)
    assert "reef_fish.ron:" in message
    assert "vision_radus" in message and "vision_radius" in message


def test_a_bad_value_names_its_setting(tiny):
    with pytest.raises(shoal.LoadError) as e:
        shoal.run(tiny, set={"scenario.groups[0].count": -1})
    assert f"{tiny}:" in str(e.value)
    assert "scenario.groups[0].count=-1" in str(e.value)
    with pytest.raises(shoal.LoadError, match="no value"):
        shoal.run(tiny, set=["scenario.duration= "])
