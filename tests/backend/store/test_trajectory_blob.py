"""A run's sampled path as one compressed blob, and back."""

import numpy as np
from numpy.testing import assert_array_equal

from backend.store.trajectory_blob import pack_trajectory, unpack_trajectory


def test_trajectory_blob_round_trip():
    columns = {
        "time": np.linspace(0.0, 3.0, 500),
        "phase": np.arange(500, dtype=np.int8) % 2,
        "jump": np.repeat(np.arange(5, dtype=np.int64), 100),
        "empty": np.empty(0),
    }
    blob = pack_trajectory(columns)
    assert isinstance(blob, bytes) and len(blob) < sum(column.nbytes for column in columns.values())
    back = unpack_trajectory(blob)
    assert list(back) == list(columns)
    for name, column in columns.items():
        assert back[name].dtype == column.dtype, name
        assert_array_equal(back[name], column, err_msg=name)


def test_unpacking_is_a_copy_not_a_view_of_a_closed_file():
    back = unpack_trajectory(pack_trajectory({"x": np.arange(3.0)}))
    back["x"][0] = 7.0
    assert back["x"].tolist() == [7.0, 1.0, 2.0]
