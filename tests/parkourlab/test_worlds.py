"""Worlds through the client (parkourlab/worlds.py), against the real service: a world file stored
and read back as written, a random one from its seed, renamed, deleted; mistakes as the client's
own exceptions, naming the field."""

import pytest

from parkourlab import Conflict, InvalidRequest
from sim_core.model.presets import get_preset
from sim_core.world.files import world_to_document
from sim_core.world.named import named_world

WALL = {
    "units": "m",
    "left": {"points": [[-0.27, 0.0], [-0.25, 0.3333333333333333], [-0.27, 0.9]], "mu": [0.6, None]},
    "right": {"points": [[0.27, 0.0], [0.27, 0.9]], "mu": ["inf"]},
}


def test_a_world_file_goes_in_and_comes_back_as_written(client):
    stored = client.create_world("client wall", world=WALL)
    assert stored["world"] == WALL and stored["source"] == "posted"
    assert client.world(stored["id"])["world"] == WALL
    assert client.rename_world(stored["id"], "client wall 2")["name"] == "client wall 2"
    assert "client wall 2" in [world["name"] for world in client.worlds(page_size=1)]
    client.delete_world(stored["id"])
    assert "client wall 2" not in [world["name"] for world in client.worlds()]


def test_named_and_random_worlds_and_mistakes(client):
    stairs = client.create_world("client stairs", named="staircase")
    expected = world_to_document(named_world("staircase", get_preset("paper").to_model().d_hat))
    assert stairs["world"]["left"]["points"] == expected["left"]["points"]
    assert client.create_world("client random", random={"seed": 11})["source"] == "random:11"
    with pytest.raises(Conflict):
        client.create_world("client stairs", named="staircase")
    with pytest.raises(InvalidRequest) as caught:
        client.create_world("broken", world=WALL | {"right": {"points": [[0.27, 0.0]]}})
    assert "world.right.points" in str(caught.value)


def test_a_run_in_a_stored_world_and_the_runs_of_a_world(client):
    world = client.create_world("client climb", named="narrowing")
    run = client.create_run([(30, 0.9)], (-1.0, 0.5), jumps=5, world_id=world["id"])
    assert run["world_id"] == world["id"] and len(run["results"]["touchdowns"]) >= 2
    assert [listed["id"] for listed in client.runs(world_id=world["id"])] == [run["id"]]
    with pytest.raises(Conflict) as caught:
        client.delete_world(world["id"])
    assert f"run {run['id']}" in str(caught.value)


def test_a_world_created_and_a_foothold_study_run_in_it(client):
    """The issue's "the client creating a world and running a foothold study"."""
    world = client.create_world("client holds", random={"seed": 2})
    job = client.submit_foothold_study(0.5, world_id=world["id"], trials=3, seed=4)
    assert job["kind"] == "foothold-study" and job["world_id"] == world["id"] and job["total"] == 1
    done = client.wait(job, timeout=600)
    result = client.results(done)["result"]
    assert [row["world"] for row in result["worlds"]] == ["client holds"]
    assert result["methods"]["placement"]["trials"] == 3 and result["trials_per_world"] == 3
    assert client.world(world["id"])["jobs"] == 1
    assert [listed["id"] for listed in client.jobs(kind="foothold-study", world_id=world["id"])] == [job["id"]]
    assert list(client.jobs(kind="plan", world_id=world["id"])) == []
    with pytest.raises(Conflict) as caught:
        client.delete_world(world["id"])
    assert f"job {job['id']}" in str(caught.value)


def test_a_plan_and_trials_in_a_world_through_the_client(client):
    world = client.create_world("client plan stairs", named="staircase")
    plan = client.results(client.wait(client.submit_plan(world["id"], 0.5), timeout=600))["result"]
    assert plan["reaches_goal"] and plan["world"] == "client plan stairs"
    trials = client.submit_world_mjtf(world["id"], [(30, 0.9)], trials=20, cap=50)
    result = client.results(client.wait(trials, timeout=600))["result"]
    assert result["trials"] == 20 and sum(result["outcomes"].values()) == 20
    with pytest.raises(InvalidRequest) as caught:
        client.submit_plan(world["id"], 99.0)
    assert "goal_height_m" in str(caught.value)
