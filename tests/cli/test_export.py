"""``parkour export``: a stored robot run and a simulated one written as MCAP, read back (cli/export.py)."""

import json

from mcap.reader import make_reader

from backend.services import runs
from backend.store.database import make_engine, migrate, session_factory, sqlite_url
from tests.backend.services.bodies import run_body
from tests.cli.helpers import invoke, json_of
from tests.robot_runs import store_robot_run


def _store_with_a_robot_run(data_dir) -> int:
    data_dir.mkdir()
    engine = make_engine(sqlite_url(data_dir))
    migrate(engine)
    with session_factory(engine)() as session:
        run_id = store_robot_run(session)
    engine.dispose()
    return run_id


def test_export_writes_the_run_s_recording(tmp_path):
    data_dir, out = tmp_path / "data", tmp_path / "climb.mcap"
    run_id = _store_with_a_robot_run(data_dir)
    printed = json_of("export", str(run_id), "--data-dir", str(data_dir), "--out", str(out))
    assert printed["path"] == str(out) and printed["bytes"] == out.stat().st_size > 0
    assert printed["channels"] == {"/tracker/pose": 336, "/touchdowns": 5, "/commands": 3, "/telemetry": 6,
                                   "/model/prediction": 5, "/robot/link": 1, "/tracker/pose_in_frame": 336,
                                   "/tracker/transform": 336, "/tracker/body": 336, "/robot/log": 4,
                                   "/world/scene": 1, "/world/points": 1,
                                   "/plot/height": 336, "/plot/touchdown/body_height": 5,
                                   "/plot/touchdown/foot_height": 5, "/plot/touchdown/rise": 4,
                                   "/plot/prediction/rise": 4}  # fmt: skip
    with out.open("rb") as stream:
        summary = make_reader(stream).get_summary()
    counts = {summary.channels[i].topic: n for i, n in summary.statistics.channel_message_counts.items()}
    assert counts == printed["channels"]
    with out.open("rb") as stream:
        (metadata,) = make_reader(stream).iter_metadata()
    assert (metadata.name, json.loads(metadata.metadata["run_id"])) == ("parkourlab.run", run_id)


def test_export_says_which_run_or_store_is_missing(tmp_path):
    data_dir = tmp_path / "data"
    run_id = _store_with_a_robot_run(data_dir)
    missing = invoke("export", "999", "--data-dir", str(data_dir), "--out", str(tmp_path / "x.mcap"))
    assert missing.exit_code == 2 and "run_id: run 999 does not exist" in missing.output
    assert not (tmp_path / "x.mcap").exists(), "nothing written"
    nowhere = invoke("export", str(run_id), "--data-dir", str(tmp_path / "elsewhere"))
    assert nowhere.exit_code == 2 and "data_dir: no store in" in nowhere.output
    assert not (tmp_path / "elsewhere").exists(), "no store made where there was none"


def test_export_writes_a_simulated_run_s_recording(tmp_path):
    data_dir, out = tmp_path / "data", tmp_path / "sim.mcap"
    _store_with_a_robot_run(data_dir)
    engine = make_engine(sqlite_url(data_dir))
    with session_factory(engine)() as session:
        with_path = runs.create_run(session, run_body(trajectory_rate=20.0)).id
        without = runs.create_run(session, run_body()).id
    engine.dispose()
    printed = json_of("export", str(with_path), "--data-dir", str(data_dir), "--out", str(out))
    assert printed["channels"] == {"/tracker/pose": 92, "/touchdowns": 5, "/tracker/pose_in_frame": 92,
                                   "/tracker/transform": 92, "/tracker/body": 92, "/plot/height": 92,
                                   "/plot/touchdown/body_height": 5, "/plot/touchdown/foot_height": 5,
                                   "/plot/touchdown/rise": 4, "/world/scene": 1, "/world/points": 1}  # fmt: skip
    with out.open("rb") as stream:
        (metadata,) = make_reader(stream).iter_metadata()
    assert (metadata.metadata["kind"], json.loads(metadata.metadata["run_id"])) == ("sim", with_path)
    refused = invoke("export", str(without), "--data-dir", str(data_dir), "--out", str(tmp_path / "none.mcap"))
    assert refused.exit_code == 2 and "stored without its path" in refused.output
    assert not (tmp_path / "none.mcap").exists()
