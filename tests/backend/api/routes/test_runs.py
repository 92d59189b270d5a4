"""Runs through the API: stored, listed, exported, compared, aggregated (backend/api/routes/runs.py)."""

import csv
import io

import pytest
from mcap.reader import make_reader

from tests.backend.api.bodies import RUN
from tests.robot_runs import store_robot_run


def test_run_matches_the_simulator_and_stores_its_path(client, auth):
    body = RUN | {"trajectory_rate": 40.0, "tags": ["a", "b"]}
    run = client.post("/api/v1/runs", json=body, headers=auth).json()
    direct = client.post("/api/v1/sim/map", json={k: RUN[k] for k in ("controls", "start", "jumps")}).json()
    assert run["results"]["states"] == direct["states"] and run["jumps_completed"] == 4
    assert run["climb"] == pytest.approx(sum(direct["rises"])) and run["tags"] == ["a", "b"]
    trajectory = client.get(f"/api/v1/runs/{run['id']}/trajectory").json()
    path = trajectory["columns"]
    assert len(path["time"]) == len(path["y"]) > 100
    assert trajectory["units"] == "nondimensional" and trajectory["column_units"]["time"] == "sqrt(l0/g)"
    assert (
        run["created_at"].endswith("Z")
        and client.get(f"/api/v1/runs/{run['id']}").json()["created_at"] == run["created_at"]
    )


def test_a_stored_run_reads_the_same_in_its_answer_its_record_and_the_list(client, auth):
    with_path = client.post("/api/v1/runs", json=RUN | {"trajectory_rate": 40.0, "tags": ["x"]}, headers=auth).json()
    without = client.post("/api/v1/runs", json=RUN, headers=auth).json()
    assert with_path["has_trajectory"] and not without["has_trajectory"]
    listed = {run["id"]: run for run in client.get("/api/v1/runs").json()["items"]}  # read in a worker process
    for run in (with_path, without):
        assert client.get(f"/api/v1/runs/{run['id']}").json() == run
        assert listed[run["id"]] == {key: value for key, value in run.items() if key != "results"}


def test_run_lists_filter_and_page(client, auth):
    for zeta0, tag in [(0.86, "low"), (0.88, "low"), (0.9, "mid"), (0.92, "high"), (0.94, "high")]:
        body = RUN | {"controls": [{"psi0_deg": 30, "zeta0": zeta0}], "tags": [tag]}
        assert client.post("/api/v1/runs", json=body, headers=auth).status_code == 201
    in_range = client.get("/api/v1/runs", params={"zeta0_min": 0.87, "zeta0_max": 0.93}).json()["items"]
    assert sorted(run["controls"][0][1] for run in in_range) == [0.88, 0.9, 0.92]
    assert [run["tags"] for run in client.get("/api/v1/runs", params={"tag": "high"}).json()["items"]] == [["high"]] * 2
    seen, cursor = [], None
    while True:
        page = client.get("/api/v1/runs", params={"limit": 2} | ({"cursor": cursor} if cursor else {})).json()
        seen += [run["id"] for run in page["items"]]
        if (cursor := page["next_cursor"]) is None:
            break
    assert seen == sorted(seen, reverse=True) and len(seen) == len(set(seen)) == 5


def _seed_runs(client, auth):
    ids = []
    for zeta0, tag in [(0.88, "low"), (0.88, "low"), (0.92, "high")]:
        body = RUN | {"controls": [{"psi0_deg": 30, "zeta0": zeta0}], "tags": [tag, "all"]}
        ids.append(client.post("/api/v1/runs", json=body, headers=auth).json()["id"])
    return ids


def test_export_csv_and_json(client, auth):
    ids = _seed_runs(client, auth)
    exported = client.get("/api/v1/runs/export", params={"format": "csv", "tag": "low"})
    assert exported.status_code == 200 and exported.headers["content-type"].startswith("text/csv")
    rows = list(csv.DictReader(io.StringIO(exported.text)))
    assert [int(row["id"]) for row in rows] == ids[:2]
    assert {"tags", "duration_s", "created_at", "climb", "leg0.zeta0", "model.alpha"} <= set(rows[0])
    assert rows[0]["tags"] == "all low"
    as_json = client.get("/api/v1/runs/export", params={"format": "json"}).json()
    assert [row["id"] for row in as_json] == ids and as_json[2]["leg0.zeta0"] == 0.92
    assert client.get("/api/v1/runs/export", params={"format": "xml"}).status_code == 422


def test_a_basket_exports_groups_and_lists_by_its_ids(client, auth):
    """Issue 40: CSV export and Group followed the filter (400 rows for a 4-run basket)."""
    ids = _seed_runs(client, auth)
    basket = [ids[2], ids[0]]
    exported = client.get("/api/v1/runs/export", params={"format": "csv", "ids": basket})
    assert sorted(int(row["id"]) for row in csv.DictReader(io.StringIO(exported.text))) == sorted(basket)
    grouped = client.get("/api/v1/runs/aggregate", params={"by": "zeta0", "ids": basket}).json()
    assert sum(group["runs"] for group in grouped["groups"]) == 2
    assert sorted(_listed(client, ids=basket)) == sorted(basket) and _listed(client, ids=basket, tag="low") == [ids[0]]
    for _ in range(2):  # the second time from the read worker's kept statement
        page = client.get("/api/v1/runs", params={"ids": [ids[1], ids[2]], "sort": "-climb"}).json()
        assert page["total"] == 2 and sorted(run["id"] for run in page["items"]) == [ids[1], ids[2]]
    too_many = client.get("/api/v1/runs", params={"ids": list(range(1, 1002))})
    assert too_many.status_code == 422 and too_many.json()["detail"][0]["loc"] == ["query", "ids"]


def test_a_robot_or_simulated_run_downloads_as_mcap(client, auth):
    with client.app.state.sessions() as session:
        robot_run = store_robot_run(session)
    response = client.get(f"/api/v1/runs/{robot_run}/export.mcap")
    assert response.status_code == 200 and response.headers["content-type"] == "application/octet-stream"
    assert response.headers["content-disposition"] == f'attachment; filename="parkourlab-run-{robot_run}.mcap"'
    summary = make_reader(io.BytesIO(response.content)).get_summary()
    counts = {summary.channels[i].topic: n for i, n in summary.statistics.channel_message_counts.items()}
    assert counts["/tracker/pose"] == 336 and counts["/touchdowns"] == 5 and counts["/model/prediction"] == 5
    replay = client.post(f"/api/v1/runs/{robot_run}/replay", headers=auth).json()
    assert client.get(f"/api/v1/runs/{replay['id']}/export.mcap").status_code == 200
    missing = client.get("/api/v1/runs/999/export.mcap")
    assert (missing.status_code, missing.json()) == (404, {"detail": "run 999 does not exist"})
    simulated = client.post("/api/v1/runs", json=RUN | {"trajectory_rate": 20.0}, headers=auth).json()
    recorded = client.get(f"/api/v1/runs/{simulated['id']}/export.mcap")
    summary = make_reader(io.BytesIO(recorded.content)).get_summary()
    counts = {summary.channels[i].topic: n for i, n in summary.statistics.channel_message_counts.items()}
    assert recorded.status_code == 200 and counts["/touchdowns"] == 5 and "/commands" not in counts
    pathless = client.post("/api/v1/runs", json=RUN, headers=auth).json()
    refused = client.get(f"/api/v1/runs/{pathless['id']}/export.mcap")
    assert refused.status_code == 409 and "sim run stored without its path" in refused.json()["detail"]
    assert client.get("/api/v1/runs/0/export.mcap").status_code == 422


def test_compare_shows_only_what_differs(client, auth):
    first, second, third = _seed_runs(client, auth)
    same = client.get("/api/v1/runs/compare", params={"ids": [first, second]}).json()
    assert set(same["differing"]) <= {"id", "created_at", "duration_s"}
    differ = client.get("/api/v1/runs/compare", params={"ids": [first, third]}).json()
    assert {"leg0.zeta0", "climb", "tags"} <= set(differ["differing"]) and "model.alpha" not in differ["fields"]
    assert [run["leg0.zeta0"] for run in differ["runs"]] == [0.88, 0.92]
    assert client.get("/api/v1/runs/compare", params={"ids": [first]}).status_code == 422
    assert client.get("/api/v1/runs/compare", params={"ids": [first, 999]}).status_code == 404


def test_aggregate_groups_runs(client, auth):
    _seed_runs(client, auth)
    by_zeta0 = client.get("/api/v1/runs/aggregate", params={"by": "zeta0"}).json()["groups"]
    assert [(group["key"], group["runs"]) for group in by_zeta0] == [(0.88, 2), (0.92, 1)]
    low = by_zeta0[0]["climb"]
    assert low["std"] == pytest.approx(0.0, abs=1e-9) and low["min"] == low["max"] == pytest.approx(low["mean"])
    by_tag = client.get("/api/v1/runs/aggregate", params={"by": "tag"}).json()["groups"]
    assert [(group["key"], group["runs"]) for group in by_tag] == [("all", 3), ("high", 1), ("low", 2)]
    assert client.get("/api/v1/runs/aggregate", params={"by": "secret"}).status_code == 422


@pytest.mark.parametrize(
    ("body", "field"),
    [
        (RUN | {"controls": [{"psi0_deg": 30, "zeta0": 1.2}]}, "zeta0"),
        (RUN | {"controls": [{"psi0_deg": 95, "zeta0": 0.9}]}, "psi0_deg"),
        (RUN | {"controls": [{"psi0_deg": 5e-324, "zeta0": 0.9}]}, "psi0_deg"),  # 0 once in radians
        (RUN | {"model": {"mu": 1e308}}, "mu"),
        (RUN | {"start": {"xdot": 0.5, "ydot": 0}}, "xdot"),
        (RUN | {"jumps": 10**7}, "jumps"),
        (RUN | {"model": {"alpha": -1}}, "alpha"),
        (RUN | {"unknown": 1}, "unknown"),
    ],
)
def test_bad_input_is_a_422_naming_the_field(client, auth, body, field):
    response = client.post("/api/v1/runs", json=body, headers=auth)
    assert response.status_code == 422
    assert any(error["loc"][-1] == field for error in response.json()["detail"]), response.json()
    assert not any(error["msg"].startswith("Value error") for error in response.json()["detail"]), "the user's words"


@pytest.mark.parametrize("moment", ["0.5", "1700000000", "yesterday", "2026-13-01"])
def test_created_before_and_after_take_only_iso_dates(client, moment):
    for name in ("created_before", "created_after"):
        response = client.get("/api/v1/runs", params={name: moment})
        assert response.status_code == 422 and response.json()["detail"][0]["loc"] == ["query", name]
        assert "ISO 8601" in response.json()["detail"][0]["msg"]


def test_an_iso_date_filters_runs(client, auth):
    client.post("/api/v1/runs", json=RUN, headers=auth)
    assert client.get("/api/v1/runs", params={"created_before": "2000-01-01"}).json()["items"] == []
    assert client.get("/api/v1/runs", params={"created_after": "2000-01-01T00:00:00Z"}).json()["items"]


def test_concurrent_clients_do_not_corrupt_state(client, auth):
    from concurrent.futures import ThreadPoolExecutor

    experiment = client.post("/api/v1/experiments", json={"name": "busy"}, headers=auth).json()["id"]

    def create(i):
        body = RUN | {"experiment_id": experiment, "jumps": 2, "tags": [f"t{i % 3}"]}
        return client.post("/api/v1/runs", json=body, headers=auth).status_code

    with ThreadPoolExecutor(8) as pool:
        codes = list(pool.map(create, range(40)))
    assert codes == [201] * 40
    assert client.get(f"/api/v1/experiments/{experiment}").json()["runs"] == 40
    counts = {g["key"]: g["runs"] for g in client.get("/api/v1/runs/aggregate", params={"by": "tag"}).json()["groups"]}
    assert counts == {"t0": 14, "t1": 13, "t2": 13}


def test_sorting_best_first_pages_by_offset(client, auth):
    for zeta0 in (0.9, 0.84, 0.94, 0.88):
        body = RUN | {"controls": [{"psi0_deg": 30, "zeta0": zeta0}]}
        client.post("/api/v1/runs", json=body, headers=auth)
    first = client.get("/api/v1/runs", params={"sort": "-climb", "limit": 3}).json()
    climbs = [run["climb"] for run in first["items"]]
    assert climbs == sorted(climbs, reverse=True) and first["next_cursor"] == 3
    rest = client.get("/api/v1/runs", params={"sort": "-climb", "limit": 3, "offset": 3}).json()
    assert len(rest["items"]) == 1 and rest["next_cursor"] is None and rest["items"][0]["climb"] < climbs[-1]
    assert client.get("/api/v1/runs", params={"sort": "password"}).status_code == 422


def test_run_with_fixed_point_and_retagging(client, auth):
    run = client.post("/api/v1/runs", json=RUN | {"fixed_point": True}, headers=auth).json()
    gait = run["results"]["fixed_point"]
    assert gait["found"] and gait["period"] == 1 and gait["max_abs_eigenvalue"] == pytest.approx(0.8486, abs=1e-4)
    lost = client.post(
        "/api/v1/runs", json=RUN | {"fixed_point": True, "start": {"xdot": -0.3, "ydot": 5.0}}, headers=auth
    ).json()
    assert lost["results"]["fixed_point"]["found"] is False and lost["failure_code"] == "no_flight"
    retagged = client.patch(f"/api/v1/runs/{run['id']}", json={"tags": ["keep", "keep", "best"]}, headers=auth)
    assert retagged.json()["tags"] == ["best", "keep"]
    assert client.patch(f"/api/v1/runs/{run['id']}", json={"climb": 9}, headers=auth).status_code == 422
    assert run["notes"] == ""
    noted = client.patch(f"/api/v1/runs/{run['id']}", json={"notes": "left foot slipped once"}, headers=auth).json()
    assert noted["notes"] == "left foot slipped once" and noted["tags"] == ["best", "keep"], "tags left out stay"
    assert client.get(f"/api/v1/runs/{run['id']}").json()["notes"] == "left foot slipped once"
    too_long = client.patch(f"/api/v1/runs/{run['id']}", json={"notes": "x" * 100_001}, headers=auth)
    assert too_long.status_code == 422 and "notes" in too_long.text


def test_a_continuous_parameter_aggregates_in_bins(client, auth):
    _seed_runs(client, auth)  # zeta0 0.88, 0.88, 0.92
    response = client.get("/api/v1/runs/aggregate", params={"by": "zeta0", "bins": 2})
    assert response.status_code == 200, response.text
    groups = response.json()["groups"]
    assert [group["runs"] for group in groups] == [2, 1], "the upper edge belongs to the last bin"
    assert groups[0]["low"] == pytest.approx(0.88) and groups[1]["high"] == pytest.approx(0.92)
    assert groups[0]["key"] == pytest.approx(0.89) and groups[1]["key"] == pytest.approx(0.91)
    assert all(isinstance(group["jumps_completed"]["mean"], float) for group in groups), "numbers, not strings"
    wrong = client.get("/api/v1/runs/aggregate", params={"by": "tag", "bins": 2})
    assert wrong.status_code == 422 and "bins" in wrong.text


def test_more_distinct_values_than_groups_allowed_ask_for_bins(client, auth, monkeypatch):
    from backend.services import runs

    _seed_runs(client, auth)
    monkeypatch.setattr(runs, "MAX_GROUPS", 1)
    response = client.get("/api/v1/runs/aggregate", params={"by": "zeta0"})
    assert response.status_code == 422 and "ask for bins" in response.text
    assert client.get("/api/v1/runs/aggregate", params={"by": "zeta0", "bins": 1}).json()["groups"][0]["runs"] == 3


def _robot_run(client, *, end_reason: str, status: str = "failed", target_m: float | None = None, tags=()) -> int:
    """A robot run that ended as ``end_reason`` says, stored as a live run stores one (no frames)."""
    from backend.robot.tracker import Calibration
    from backend.schemas import ClosedLoopIn, LegIn, RobotRunCreate
    from backend.services.robot_records import fold_journal, open_robot_run
    from sim_core import get_preset

    closed_loop = None if target_m is None else ClosedLoopIn(target_m=target_m)
    legs = [LegIn(psi0_deg=35, zeta0=0.9)] * 2
    request = RobotRunCreate(controls=legs, jumps=15, closed_loop=closed_loop, tags=list(tags))
    with client.app.state.sessions() as session:
        run_id = open_robot_run(session, request, get_preset("paper"), Calibration())
        fold_journal(session, run_id, status=status, end_reason=end_reason, disarm="disarmed")
    return run_id


def _listed(client, **params) -> list[int]:
    return [run["id"] for run in client.get("/api/v1/runs", params=params | {"limit": 500}).json()["items"]]


def test_a_page_says_how_many_runs_match_and_any_page_can_be_asked_for(client, auth):
    ids = [client.post("/api/v1/runs", json=RUN | {"tags": [f"t{k % 2}"]}, headers=auth).json()["id"] for k in range(7)]
    first = client.get("/api/v1/runs", params={"limit": 3}).json()
    assert first["total"] == 7 and [run["id"] for run in first["items"]] == ids[::-1][:3]
    third = client.get("/api/v1/runs", params={"limit": 3, "offset": 6}).json()
    assert (third["total"], [run["id"] for run in third["items"]], third["next_cursor"]) == (7, [ids[0]], None)
    climb = client.get("/api/v1/runs", params={"limit": 3, "offset": 3, "sort": "climb", "tag": "t0"}).json()
    assert (climb["total"], len(climb["items"]), climb["next_cursor"]) == (4, 1, None)
    assert client.get("/api/v1/runs", params={"tag": "none"}).json() == {"items": [], "next_cursor": None, "total": 0}
    client.delete(f"/api/v1/runs/{ids[0]}", headers=auth)
    assert client.get("/api/v1/runs", params={"limit": 3}).json()["total"] == 6, "a deleted run is not counted"
    for listed in ("/api/v1/experiments", "/api/v1/jobs"):
        page = client.get(listed).json()
        assert page["total"] == len(page["items"]) == 0 and page["next_cursor"] is None


def test_runs_say_how_they_ended_and_were_driven_and_filter_and_sort_by_it(client, auth):
    """A robot run's end reason, loop, controller, target and touchdowns: listed, filtered (an
    end reason as recorded or by its kind, "error" for "error: …"), sorted, compared, exported."""
    sim = client.post("/api/v1/runs", json=RUN, headers=auth).json()
    assert (sim["end_reason"], sim["loop"], sim["controller"], sim["target"], sim["touchdowns"]) == (
        None, "open", None, None, None)  # fmt: skip
    estop = _robot_run(client, end_reason="e-stop", target_m=0.55)
    fell_reason = "robot disarmed (fell or timed out)"
    fell = _robot_run(client, end_reason=fell_reason)
    error = _robot_run(client, end_reason="error: the link write timed out", target_m=0.4)
    done = _robot_run(client, end_reason="jumps done", status="done")
    listed = {run["id"]: run for run in client.get("/api/v1/runs").json()["items"]}
    assert {key: listed[estop][key] for key in ("status", "end_reason", "loop", "controller", "target")} == {
        "status": "failed", "end_reason": "e-stop", "loop": "closed", "controller": "pid", "target": 0.55}  # fmt: skip
    assert listed[done]["touchdowns"] == 0 and listed[done]["loop"] == "open"
    assert _listed(client, end_reason="e-stop") == [estop]
    assert _listed(client, end_reason="error") == [error], "a kind of end reason"
    assert _listed(client, end_reason="error: the link write timed out") == [error]
    assert _listed(client, end_reason="err") == []
    assert _listed(client, loop="closed") == [error, estop]
    assert _listed(client, controller="pid", status="failed") == [error, estop]
    assert _listed(client, status="done", kind="robot") == [done]
    assert _listed(client, sort="target") == [sim["id"], fell, done, error, estop], "nulls first, ties by id"
    assert _listed(client, sort="-target") == [estop, error, done, fell, sim["id"]]
    assert _listed(client, sort="end_reason", kind="robot") == [estop, error, done, fell]
    assert client.get("/api/v1/runs", params={"loop": "sideways"}).status_code == 422
    compared = client.get("/api/v1/runs/compare", params={"ids": [estop, done]}).json()
    assert {"end_reason", "loop", "controller", "target", "status"} <= set(compared["differing"])
    rows = list(csv.DictReader(io.StringIO(client.get("/api/v1/runs/export", params={"format": "csv"}).text)))
    by_id = {int(row["id"]): row for row in rows}
    assert (by_id[estop]["end_reason"], by_id[estop]["loop"], by_id[estop]["target"]) == ("e-stop", "closed", "0.55")
    assert by_id[estop]["controller"] == "pid" and by_id[sim["id"]]["loop"] == "open"
    as_json = {row["id"]: row for row in client.get("/api/v1/runs/export", params={"format": "json"}).json()}
    assert as_json[fell]["end_reason"] == fell_reason and as_json[fell]["target"] is None
    by_ending = client.get("/api/v1/runs/aggregate", params={"by": "end_reason", "kind": "robot"}).json()["groups"]
    assert {group["key"]: group["runs"] for group in by_ending} == {"e-stop": 1, "error: the link write timed out": 1,
                                                                    "jumps done": 1, fell_reason: 1}  # fmt: skip


def test_a_robot_run_counts_its_touchdowns_as_its_jumps(client, auth):
    """A robot run asked for 5 jumps records 5 touchdowns; jumps_completed counts the 4 measured between them."""
    with client.app.state.sessions() as session:
        robot_run = store_robot_run(session)
    run = client.get(f"/api/v1/runs/{robot_run}").json()
    assert (run["jumps"], run["touchdowns"], run["jumps_completed"]) == (5, 5, 4)
    replay = client.post(f"/api/v1/runs/{robot_run}/replay", headers=auth).json()
    assert (replay["touchdowns"], replay["loop"], replay["end_reason"]) == (5, "open", None)


def test_search_finds_text_in_notes_and_tags_in_any_case(client, auth):
    runs = [client.post("/api/v1/runs", json=RUN | {"tags": tags}, headers=auth).json()["id"]
            for tags in (["wet-wall"], ["dry"], ["dry"])]  # fmt: skip
    client.patch(f"/api/v1/runs/{runs[1]}", json={"notes": "Left foot SLIPPED on a WET patch"}, headers=auth)
    client.patch(f"/api/v1/runs/{runs[2]}", json={"notes": "50% humidity_high"}, headers=auth)
    assert _listed(client, q="wet") == [runs[1], runs[0]]
    assert _listed(client, q="Slipped") == [runs[1]]
    assert _listed(client, q="50%") == [runs[2]] and _listed(client, q="% h") == [runs[2]], "% is a character"
    assert _listed(client, q="y_h") == [runs[2]] and _listed(client, q="ty_") == [runs[2]], "_ is a character"
    assert _listed(client, q="%%%") == [] and _listed(client, q="___") == [], "no wildcards"
    assert _listed(client, q='"50') == [] and _listed(client, q="wet OR dry") == [], "nor a search language"
    assert _listed(client, q="wet-wall") == [runs[0]] and _listed(client, q="SLIPPED on a") == [runs[1]]
    short = client.get("/api/v1/runs", params={"q": " ab "})
    assert short.status_code == 422 and short.json()["detail"][0]["loc"] == ["query", "q"]
    assert "at least 3 characters" in short.json()["detail"][0]["msg"]
    assert client.get("/api/v1/runs", params={"q": "wet", "limit": 1}).json()["total"] == 2
    assert _listed(client, q="  ") == _listed(client), "blank: no search"
    assert client.get("/api/v1/runs", params={"q": "x" * 201}).status_code == 422


def test_the_aggregate_gives_each_means_95_percent_interval(client, auth):
    for zeta0 in (0.88, 0.88, 0.88, 0.92):
        start = {"xdot": -0.93, "ydot": -0.2 + zeta0 / 100}
        body = RUN | {"controls": [{"psi0_deg": 30, "zeta0": zeta0}], "start": start}
        client.post("/api/v1/runs", json=body, headers=auth)
    groups = client.get("/api/v1/runs/aggregate", params={"by": "zeta0"}).json()["groups"]
    three = groups[0]["climb"]
    assert three["ci95_low"] <= three["mean"] <= three["ci95_high"]
    assert groups[1]["climb"]["ci95_low"] is None, "one run: no interval"
