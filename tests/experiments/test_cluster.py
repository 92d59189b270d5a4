"""The Dask path: a LocalCluster of worker processes gives exactly the in-process results."""

import math

import numpy as np
import pytest

from experiments.cluster import SCHEDULER_ENV, chunk_map_for, scheduler_address
from sim_core import ParameterError, find_fixed_point
from sim_core.basins.basin import BasinGrid, compute_basin
from sim_core.basins.sweep import energy_sweep
from sim_core.model.noise import NoiseModel
from sim_core.robustness.mjtf import mjtf_study

pytestmark = pytest.mark.slow  # starts worker processes (a few seconds)


@pytest.fixture(scope="module")
def scheduler():
    from distributed import LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        yield cluster.scheduler_address


@pytest.fixture(scope="module")
def gait(paper, symmetric):
    return find_fixed_point(paper, symmetric, 1, (-0.9, -0.2))


def test_basin_on_the_cluster_equals_in_process(paper, symmetric, gait, scheduler):
    grid = BasinGrid.around(gait.state, 30)
    local = compute_basin(paper, symmetric, gait, grid, chunk_cells=128)
    with chunk_map_for(scheduler) as chunk_map:
        seen = []
        remote = compute_basin(
            paper, symmetric, gait, grid, chunk_cells=128, chunk_map=chunk_map, progress=lambda *p: seen.append(p)
        )
    np.testing.assert_array_equal(remote.jumps_to_converge, local.jumps_to_converge)
    np.testing.assert_array_equal(remote.failure, local.failure)
    assert seen[-1] == (8, 8), "progress per finished chunk"


def test_mjtf_on_the_cluster_equals_in_process(paper, scheduler):
    options = {"noise": NoiseModel(), "trials": 12, "cap": 200, "seed": 11, "guess": (-0.93, -0.2)}
    local = mjtf_study(paper, math.radians(30.0), [0.88, 0.94], chunk_trials=12, **options)
    with chunk_map_for(scheduler) as chunk_map:
        remote = mjtf_study(paper, math.radians(30.0), [0.88, 0.94], chunk_trials=5, chunk_map=chunk_map, **options)
    for a, b in zip(local.levels, remote.levels, strict=True):
        np.testing.assert_array_equal(a.jumps, b.jumps)
        np.testing.assert_array_equal(a.status, b.status)


def test_sweep_basins_on_the_cluster_equal_in_process(paper, scheduler):
    options = {"guess": (-0.93, -0.2), "basin_grid": BasinGrid((-2.5, -0.05), (-1.8, 1.6), 16)}
    local = energy_sweep(paper, math.radians(30.0), [0.88, 0.92], **options)
    with chunk_map_for(scheduler) as chunk_map:
        remote = energy_sweep(paper, math.radians(30.0), [0.88, 0.92], chunk_map=chunk_map, **options)
    np.testing.assert_array_equal(remote.basin_area, local.basin_area)


def test_unreachable_scheduler_is_a_clear_error():
    with (
        pytest.raises(ParameterError, match=r"^scheduler: cannot reach"),
        chunk_map_for("tcp://127.0.0.1:9", timeout="1s"),
    ):
        pass


def test_scheduler_address_from_option_or_environment(monkeypatch):
    monkeypatch.setenv(SCHEDULER_ENV, "tcp://example:8786")
    assert scheduler_address(None) == "tcp://example:8786"
    assert scheduler_address("tcp://other:1") == "tcp://other:1"
    monkeypatch.delenv(SCHEDULER_ENV)
    assert scheduler_address(None) is None


def test_cli_basin_on_the_cluster_matches_in_process(scheduler):
    from typer.testing import CliRunner

    from cli.app import app

    args = ["basin", "--guess", "-0.9", "-0.2", "--grid", "12", "--jumps", "30", "--json"]
    runner = CliRunner()
    local = runner.invoke(app, args)
    remote = runner.invoke(app, [*args, "--scheduler", scheduler])
    assert local.exit_code == 0 and remote.exit_code == 0, remote.output
    assert remote.stdout == local.stdout


def test_a_control_study_on_the_cluster_equals_in_process(scheduler):
    """The benchmark's chunks (a controller's trials, 50 seeds each) on two worker processes: the
    same outcome as in-process, to the last digit, but for the law's own timing."""
    from experiments.control_study import Config, run
    from sim_core.model.presets import get_preset

    robot = get_preset("paper")
    config = Config(controllers=("pid", "deadbeat"), jumps=80, seeds=60, seed0=5)
    with chunk_map_for(scheduler) as chunk_map:
        clustered = run(robot.to_model(), robot.leg_length, config, chunk_map=chunk_map).to_dict()
    local = run(robot.to_model(), robot.leg_length, config).to_dict()
    for entry in (*clustered["controllers"], *local["controllers"]):
        entry.pop("us_per_jump")
    assert clustered == local
