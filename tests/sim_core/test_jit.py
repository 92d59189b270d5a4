"""How sim_core compiles (sim_core._jit): a cache directory keyed on all of sim_core's source (its packages too) and
numba's version, placed where the environment says, and kernels on numpy's error model."""

import shutil
from pathlib import Path

import numba
import numpy as np
import pytest

from sim_core import _jit

SIM_CORE = Path(_jit.__file__).parent


@pytest.fixture
def source_copy(tmp_path, monkeypatch) -> Path:
    """A copy of sim_core's modules that ``_jit`` hashes instead of the real ones."""
    copy = tmp_path / "sim_core"
    shutil.copytree(SIM_CORE, copy, ignore=shutil.ignore_patterns("__pycache__"))
    monkeypatch.setattr(_jit, "__file__", str(copy / "_jit.py"))
    return copy


@pytest.fixture
def numba_cache_dir():
    """Restores numba's cache directory after a test that points it elsewhere."""
    before = numba.config.CACHE_DIR
    yield
    numba.config.CACHE_DIR = before


def test_the_hash_is_of_the_source_as_it_is(source_copy):
    assert _jit._source_hash() == _jit.CACHE_DIR.name, "the same files, the same directory"
    assert len(_jit.CACHE_DIR.name) == 16 and int(_jit.CACHE_DIR.name, 16) >= 0


def test_any_module_edited_changes_the_hash(source_copy):
    """numba notices an edit of a kernel's own file only; an inlined kernel's file (here: the stance
    equations, in the model package) must start a clean cache too."""
    before = _jit._source_hash()
    equations = source_copy / "model" / "stance_equations.py"
    equations.write_text(equations.read_text() + "\n# edited\n")
    assert _jit._source_hash() != before


def test_a_new_module_or_another_numba_changes_the_hash(source_copy, monkeypatch):
    before = _jit._source_hash()
    (source_copy / "control" / "new_kernels.py").write_text("")
    with_new = _jit._source_hash()
    assert with_new != before
    monkeypatch.setattr(numba, "__version__", "0.0.0")
    assert _jit._source_hash() != with_new


def test_the_cache_lives_where_the_environment_says(tmp_path, monkeypatch, numba_cache_dir):
    monkeypatch.setenv("PARKOUR_CACHE_DIR", str(tmp_path / "cache"))
    directory = _jit.configure()
    assert directory == tmp_path / "cache" / "numba" / _jit._source_hash()
    assert str(directory) == numba.config.CACHE_DIR
    monkeypatch.delenv("PARKOUR_CACHE_DIR")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert _jit.configure() == tmp_path / "xdg" / "parkourlab" / "numba" / _jit._source_hash()


def test_a_kernel_is_cached_in_the_configured_directory(tmp_path, monkeypatch, numba_cache_dir):
    monkeypatch.setenv("PARKOUR_CACHE_DIR", str(tmp_path))
    directory = _jit.configure()

    @_jit.kernel
    def ratio(a, b):
        return a / b

    assert ratio(1.0, 4.0) == 0.25
    assert any(directory.rglob("*.nbi")), "the compiled kernel is indexed in the cache directory"


def test_kernels_divide_by_zero_as_numpy_does():
    """numpy's error model: inf and NaN instead of ZeroDivisionError (the kernels never raise)."""

    @_jit.kernel(cache=False)
    def ratio(a, b):
        return a / b

    assert ratio(1.0, 0.0) == np.inf and np.isnan(ratio(0.0, 0.0))


def test_parallel_kernels_share_the_work_across_threads():
    @_jit.parallel_kernel(cache=False)
    def total(values):
        result = 0.0
        for i in numba.prange(values.size):
            result += values[i]
        return result

    values = np.arange(1000.0)
    assert total(values) == values.sum()
