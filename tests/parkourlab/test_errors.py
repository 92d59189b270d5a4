"""parkourlab/errors.py: each status its exception, fields named as the request spells them."""

import pytest

from parkourlab.errors import (
    ApiError,
    Conflict,
    InvalidRequest,
    NotFound,
    QueueFull,
    ServiceUnavailable,
    Unauthorized,
    error_for,
    field_name,
)

STATUSES = [(401, Unauthorized), (404, NotFound), (409, Conflict), (422, InvalidRequest), (429, QueueFull),
            (503, ServiceUnavailable), (500, ApiError)]  # fmt: skip


@pytest.mark.parametrize(("status", "kind"), STATUSES)
def test_each_status_its_exception(status, kind):
    error = error_for(status, {"detail": "why"}, "GET /api/v1/x")
    assert type(error) is kind and error.status == status and error.detail == "why"
    assert error.errors == [{"field": "", "message": "why"}]
    assert str(error).startswith(f"GET /api/v1/x: {status} ") and str(error).endswith(": why")


@pytest.mark.parametrize(
    ("loc", "field"),
    [
        (["body", "controls", 0, "zeta0"], "controls[0].zeta0"),
        (["query", "limit"], "limit"),
        (["path", "run_id"], "run_id"),
        (["body", "model.preset"], "model.preset"),
        ([], ""),
    ],
)
def test_field_names(loc, field):
    assert field_name(loc) == field


def test_a_422_lists_every_field_once():
    detail = [
        {"loc": ["body", "jumps"], "msg": "Input should be greater than or equal to 1", "input": 0},
        {"loc": ["body", "model.preset"], "msg": "model.preset: unknown preset 'x'", "type": "value_error"},
        {"loc": [], "msg": "and 3 more errors", "type": "too_many_errors"},
    ]
    error = error_for(422, {"detail": detail})
    assert error.errors == [
        {"field": "jumps", "message": "Input should be greater than or equal to 1 (got 0)"},
        {"field": "model.preset", "message": "unknown preset 'x'"},
        {"field": "", "message": "and 3 more errors"},
    ]
    assert "model.preset: unknown preset 'x'" in str(error) and "model.preset: model.preset" not in str(error)


def test_a_body_that_is_not_json():
    error = error_for(502, "Bad Gateway")
    assert type(error) is ApiError and error.errors == [{"field": "", "message": "Bad Gateway"}]
