"""The statuses each operation answers, in the OpenAPI document (backend/api/statuses.py); the fuzz
test (test_schema_fuzz.py) holds the service's answers to it."""

import pytest

from backend.api.app import create_app
from backend.api.statuses import BY_OPERATION
from backend.settings import Settings


@pytest.fixture(scope="module")
def document(tmp_path_factory):
    return create_app(Settings.from_environment(tmp_path_factory.mktemp("data")), run_jobs=False).openapi()


def _operations(document):
    return [(method.upper(), path, op) for path, ops in document["paths"].items() for method, op in ops.items()]


def test_every_operation_lists_the_middlewares_400_and_writes_their_413_and_507(document):
    for method, path, operation in _operations(document):
        assert "400" in operation["responses"], (method, path)
        if method != "GET":
            assert {"413", "507"} <= set(operation["responses"]), (method, path)


def test_the_token_routes_list_401_and_the_open_ones_do_not(document):
    statuses = {(method, path): set(op["responses"]) for method, path, op in _operations(document)}
    assert "401" in statuses["POST", "/api/v1/runs"] and "401" in statuses["DELETE", "/api/v1/runs/{run_id}"]
    assert "401" not in statuses["POST", "/api/v1/robot/estop"], "anyone may press the e-stop"
    assert "401" not in statuses["GET", "/api/v1/runs"], "reads are open"


def test_what_only_some_operations_answer(document):
    statuses = {(method, path): set(op["responses"]) for method, path, op in _operations(document)}
    assert "429" in statuses["POST", "/api/v1/jobs"]
    assert "409" in statuses["DELETE", "/api/v1/experiments/{experiment_id}"]
    assert {"409", "503"} <= statuses["POST", "/api/v1/robot/arm"]
    assert "404" in statuses["GET", "/api/v1/runs/{run_id}"], "a path naming a record"


def test_the_table_names_only_operations_that_exist(document):
    operations = {(method, path) for method, path, _ in _operations(document)}
    assert set(BY_OPERATION) <= operations, set(BY_OPERATION) - operations


def test_each_error_is_described_with_its_json_body(document):
    for method, path, operation in _operations(document):
        for code, response in operation["responses"].items():
            if code.startswith("4") and code != "422":
                assert response["description"] and "application/json" in response["content"], (method, path, code)
