"""The backend's domain errors (backend/errors.py): what they say, what they are, and that the API's
table gives each one a status a client can act on (backend/api/errors.py)."""

import inspect
import pickle

import pytest

from backend import errors
from backend.errors import Conflict, NotFound, QueueFull

DOMAIN_ERRORS = [
    kind for _name, kind in inspect.getmembers(errors, inspect.isclass) if kind.__module__ == errors.__name__
]


def test_not_found_names_the_kind_of_record_and_its_id():
    error = NotFound("run", 42)
    assert str(error) == "run 42 does not exist"
    assert str(NotFound("trajectory of run", 7)) == "trajectory of run 7 does not exist"


def test_not_found_is_a_lookup_error_and_conflict_a_runtime_error():
    """Callers that catch the built-in kinds (``except LookupError``) keep catching them."""
    with pytest.raises(LookupError):
        raise NotFound("job", 3)
    with pytest.raises(RuntimeError, match=r"^experiment 1 still has 2 runs$"):
        raise Conflict("experiment 1 still has 2 runs")


def test_each_domain_error_has_its_status_in_the_apis_table():
    from backend.api.errors import STATUS_OF  # the API's side: loaded only here

    assert sorted(kind.__name__ for kind in DOMAIN_ERRORS) == ["Conflict", "NotFound", "QueueFull"]
    assert {kind: STATUS_OF[kind][0] for kind in DOMAIN_ERRORS} == {NotFound: 404, Conflict: 409, QueueFull: 429}


@pytest.mark.parametrize(
    "error", [NotFound("run", 42), Conflict("experiment 1 still has 2 runs"), QueueFull("the job queue is full")]
)
def test_domain_errors_cross_process_boundaries_as_made(error):
    """The store is read in worker processes: an error raised there is pickled back to the service."""
    copy = pickle.loads(pickle.dumps(error))
    assert type(copy) is type(error) and str(copy) == str(error)
