"""parkourlab/types.py against the API: each TypedDict has exactly the keys of the response model the
service answers with (backend/schemas), each Literal exactly the values of its enum, and RunFilters
exactly the run filters the API reads, so a field added, renamed or dropped on one side fails here
rather than in a script. The client itself imports none of the backend; only this test does."""

from __future__ import annotations

import typing

import pytest

from parkourlab import types

# Each answer's TypedDict and the response model of the API that it is the client's name for.
ANSWERS = {
    "Run": "RunOut",
    "RunDetail": "RunDetail",
    "Experiment": "ExperimentOut",
    "Job": "JobOut",
    "MJTFLevel": "MJTFLevelOut",
    "JobResults": "JobResults",
    "Page": "Page",
}
# The routes the client reads a typed answer from: (method, path) -> its TypedDict, or ("Page", item).
ROUTES = {
    ("POST", "/api/v1/runs"): "RunDetail",
    ("GET", "/api/v1/runs"): ("Page", "Run"),
    ("GET", "/api/v1/runs/{run_id}"): "RunDetail",
    ("PATCH", "/api/v1/runs/{run_id}"): "Run",
    ("POST", "/api/v1/experiments"): "Experiment",
    ("GET", "/api/v1/experiments"): ("Page", "Experiment"),
    ("GET", "/api/v1/experiments/{experiment_id}"): "Experiment",
    ("PATCH", "/api/v1/experiments/{experiment_id}"): "Experiment",
    ("POST", "/api/v1/jobs"): "Job",
    ("GET", "/api/v1/jobs"): ("Page", "Job"),
    ("GET", "/api/v1/jobs/{job_id}"): "Job",
    ("GET", "/api/v1/jobs/{job_id}/results"): "JobResults",
    ("POST", "/api/v1/jobs/{job_id}/cancel"): "Job",
}
ENUMS = {"RunKind": "RunKind", "RunStatus": "RunStatus", "RunLoop": "RunLoop", "JobState": "JobState"}


def typed_keys(typed_dict) -> set[str]:
    return set(typed_dict.__required_keys__ | typed_dict.__optional_keys__)


def api_keys(model) -> set[str]:
    """The keys of ``model``'s JSON as the API sends it (by alias, computed fields included)."""
    fields = {field.serialization_alias or field.alias or name for name, field in model.model_fields.items()}
    return fields | set(model.model_computed_fields)


def difference(typed_dict, model) -> str:
    mine, theirs = typed_keys(typed_dict), api_keys(model)
    return f"the API's {model.__name__} adds {sorted(theirs - mine)}, lacks {sorted(mine - theirs)}"


@pytest.mark.parametrize(("name", "model_name"), sorted(ANSWERS.items()))
def test_each_answer_has_the_keys_of_the_apis_model(name, model_name):
    from backend import schemas

    typed_dict, model = getattr(types, name), getattr(schemas, model_name)
    assert typed_keys(typed_dict) == api_keys(model), difference(typed_dict, model)


def test_every_key_an_answer_is_sure_to_have_is_required():
    """The API sends every field of its models (null where it has none), so no key is optional."""
    for name in ANSWERS:
        assert getattr(types, name).__optional_keys__ == frozenset(), name


def test_nested_answers_are_the_typed_ones():
    hints = typing.get_type_hints(types.JobResults)
    assert hints["job"] is types.Job and hints["levels"] == list[types.MJTFLevel] | None
    assert typing.get_type_hints(types.RunDetail)["results"] == dict[str, typing.Any]


def test_the_client_reads_each_typed_answer_from_the_route_that_sends_that_model():
    from backend import schemas
    from backend.api.routes import experiments, jobs, runs

    response_models = {
        (method, route.path): route.response_model
        for module in (runs, experiments, jobs)
        for route in module.router.routes
        for method in route.methods
    }
    for (method, path), answer in ROUTES.items():
        model = response_models[method, path]
        if isinstance(answer, tuple):
            _, item = answer
            generic = model.__pydantic_generic_metadata__
            assert generic["origin"] is schemas.Page, f"{method} {path} answers {model.__name__}, not a page"
            assert generic["args"] == (getattr(schemas, ANSWERS[item]),), f"{method} {path}: {model.__name__}"
        else:
            expected = getattr(schemas, ANSWERS[answer])
            assert model is expected, f"{method} {path} answers {model.__name__}, not {expected.__name__} ({answer})"


@pytest.mark.parametrize(("name", "enum_name"), sorted(ENUMS.items()))
def test_each_literal_has_the_values_of_the_apis_enum(name, enum_name):
    from backend import schemas

    assert set(typing.get_args(getattr(types, name))) == {member.value for member in getattr(schemas, enum_name)}


def test_final_job_states_are_the_services():
    from backend.services.jobs import FINAL

    assert {state.value for state in FINAL} == types.FINAL_JOB_STATES
    assert set(typing.get_args(types.JobState)) >= types.FINAL_JOB_STATES


def test_run_filters_are_the_query_parameters_the_api_reads():
    """The client refuses a filter not in RunFilters (the API would ignore it and match every run):
    so RunFilters must name each filter the API takes, by its query name."""
    from fastapi.dependencies.utils import get_dependant

    from backend.api.deps import run_filter

    query = {parameter.alias for parameter in get_dependant(path="", call=run_filter).query_params}
    assert set(types.RunFilters.__annotations__) == query == types.RUN_FILTERS, (
        f"the API adds {sorted(query - types.RUN_FILTERS)}, lacks {sorted(types.RUN_FILTERS - query)}"
    )
