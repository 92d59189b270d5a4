"""sim_core/robustness/mfpt_cache.py: a repeated MFPT loads its chains, anything the chain depends on misses,
a damaged entry is rebuilt, and the cache stays within its bounds."""

import math
import os
import shutil
from dataclasses import replace

import numpy as np
import pytest
from scipy import sparse

import sim_core._jit
from sim_core.model.controls import ControlSchedule, LegControl
from sim_core.model.noise import NoiseModel
from sim_core.robustness import mfpt_cache
from sim_core.robustness.mfpt import mfpt
from sim_core.robustness.mfpt_cache import ChainCache, chain_key
from sim_core.robustness.mfpt_chain import Chain
from sim_core.robustness.mfpt_grid import ChainGrid
from sim_core.section.gait_search import gait_of

CONTROLS = LegControl(math.radians(30), 0.96)
GRID = ChainGrid(velocity_nodes=8, pitch_spacing=2.0, paths=50, path_jumps=500)  # the cheapest the tests use
NOISE = NoiseModel()


@pytest.fixture(scope="module")
def start(paper):
    return np.asarray(gait_of(paper, ControlSchedule((CONTROLS,)), guess=(-0.93, 0.2)).state)


@pytest.fixture(scope="module")
def built(paper, start, tmp_path_factory):
    """One MFPT that built and stored both chains, and the directory it stored them in."""
    directory = tmp_path_factory.mktemp("built")
    return mfpt(paper, CONTROLS, NOISE, start=start, grid=GRID, cache=ChainCache(directory)), directory


def _copy(directory, tmp_path):
    return ChainCache(shutil.copytree(directory, tmp_path / "cache"))


def _same_numbers(one, other):
    assert [e.mfpt_jumps for e in one.estimates] == [e.mfpt_jumps for e in other.estimates]
    # ARPACK starts from a random vector: lambda2 agrees to its tolerance, not to the last bit, built or loaded.
    assert [e.lambda2 for e in one.estimates] == pytest.approx([e.lambda2 for e in other.estimates], rel=1e-10)
    assert (one.discretisation_error, one.cells) == (other.discretisation_error, other.cells)


def test_a_second_call_loads_both_chains_and_gives_the_same_numbers(paper, start, built, tmp_path):
    first, directory = built
    assert first.to_dict()["cached"] == [False, False]
    assert len(list(directory.glob("*.npz"))) == 2
    progress = []
    cache = _copy(directory, tmp_path)
    again = mfpt(
        paper, CONTROLS, NOISE, start=start, grid=GRID, cache=cache, progress=lambda *done: progress.append(done)
    )
    payload = again.to_dict()
    assert payload["cached"] == [True, True] and [grid["cached"] for grid in payload["grids"]] == [True, True]
    _same_numbers(first, again)
    assert progress[-1][0] == progress[-1][1], "progress reaches its total from the cache too"


def test_the_default_cache_lives_under_the_root_and_the_environment_turns_it_off(
    paper, start, built, tmp_path, monkeypatch
):
    _, directory = built
    root = tmp_path / "root"
    shutil.copytree(directory, root)
    monkeypatch.setattr(mfpt_cache, "cache_root", lambda: root)
    assert mfpt(paper, CONTROLS, NOISE, start=start, grid=GRID).to_dict()["cached"] == [True, True]
    monkeypatch.setenv("PARKOUR_MFPT_CACHE", "0")
    assert mfpt(paper, CONTROLS, NOISE, start=start, grid=GRID).to_dict()["cached"] == [False, False]
    assert mfpt(paper, CONTROLS, NOISE, start=start, grid=GRID, cache=False).to_dict()["cached"] == [False, False]


def test_the_root_is_numbas_beside_its_source_hash():
    assert mfpt_cache.cache_root() == sim_core._jit.CACHE_DIR.parent.parent / "mfpt"


@pytest.mark.parametrize(
    "change",
    [
        {"model": lambda model: replace(model, mu=model.mu * 1.01)},
        {"controls": LegControl(math.radians(30), 0.95)},
        {"noise": replace(NOISE, velocity=NOISE.velocity * 1.5)},
        {"noise": replace(NOISE, pitch_drift_deg=NOISE.pitch_drift_deg + 0.1)},
        {"start": np.array([-0.93, 0.2000001])},
        {"grid": replace(GRID, velocity_nodes=9)},
        {"grid": replace(GRID, paths=51)},
        {"grid": replace(GRID, strata=(3, 2, 2, 3))},
    ],
)
def test_anything_the_chain_depends_on_changes_the_key(paper, change):
    inputs = {"model": paper, "controls": CONTROLS, "noise": NOISE, "start": np.array([-0.93, 0.2]), "grid": GRID}
    changed = {**inputs, **change}
    if callable(changed["model"]):
        changed["model"] = changed["model"](paper)
    assert chain_key(**inputs) == chain_key(**dict(inputs))
    assert chain_key(**changed) != chain_key(**inputs)


def test_a_change_of_source_misses(paper, monkeypatch):
    args = (paper, CONTROLS, NOISE, np.array([-0.93, 0.2]), GRID)
    before = chain_key(*args)
    monkeypatch.setattr(sim_core._jit, "CACHE_DIR", sim_core._jit.CACHE_DIR.parent / "0123456789abcdef")
    assert chain_key(*args) != before


@pytest.mark.parametrize("damage", ["garbage", "truncated", "empty", "another_key"])
def test_a_damaged_entry_is_rebuilt(paper, start, built, tmp_path, damage):
    first, directory = built
    cache = _copy(directory, tmp_path)
    entries = sorted(cache.directory.glob("*.npz"))
    victim, other = entries
    if damage == "garbage":
        victim.write_bytes(b"not a zip")
    elif damage == "truncated":
        victim.write_bytes(victim.read_bytes()[: victim.stat().st_size // 2])
    elif damage == "empty":
        victim.write_bytes(b"")
    else:
        shutil.copyfile(other, victim)
    again = mfpt(paper, CONTROLS, NOISE, start=start, grid=GRID, cache=cache)
    assert sorted(again.to_dict()["cached"]) == [False, True]
    _same_numbers(first, again)
    assert mfpt(paper, CONTROLS, NOISE, start=start, grid=GRID, cache=cache).to_dict()["cached"] == [True, True]


def _tiny_chain(value: float) -> Chain:
    steps = sparse.csr_matrix(np.array([[1.0]]))
    jumps = sparse.csr_matrix(np.array([[value]]))
    axis = np.array([0.0])
    return Chain(axis, axis, axis, np.zeros((1, 1), dtype=np.int64), steps, jumps, np.array([value]), 0.0)


def test_a_stored_chain_reads_back_whole(tmp_path):
    cache = ChainCache(tmp_path)
    assert cache.store("a", _tiny_chain(0.5))
    chain = cache.load("a")
    assert chain.transitions().toarray().tolist() == [[0.5]] and chain.states == 1
    assert cache.load("b") is None
    assert [path.name for path in tmp_path.iterdir()] == ["a.npz"], "no temporary file is left"


def test_the_least_recently_used_entries_go_past_the_bounds(tmp_path):
    cache = ChainCache(tmp_path, max_entries=2)
    for age, key in enumerate(("old", "used", "new")):
        cache.store(key, _tiny_chain(0.5))
        os.utime(cache.path(key), (1000 + age, 1000 + age))
    assert sorted(path.stem for path in tmp_path.glob("*.npz")) == ["new", "used"]
    os.utime(cache.path("new"), (1000, 1000))
    assert cache.load("used") is not None  # a hit makes it the newest
    cache.store("newer", _tiny_chain(0.5))
    assert sorted(path.stem for path in tmp_path.glob("*.npz")) == ["newer", "used"]
    size = cache.path("used").stat().st_size
    ChainCache(tmp_path, max_bytes=size).evict()
    assert len(list(tmp_path.glob("*.npz"))) == 1


def test_a_cache_that_cannot_be_written_is_no_error(tmp_path):
    blocked = tmp_path / "file"
    blocked.write_text("")
    assert ChainCache(blocked / "mfpt").store("a", _tiny_chain(0.5)) is False
    assert ChainCache(blocked / "mfpt").load("a") is None
