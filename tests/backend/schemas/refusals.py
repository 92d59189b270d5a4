"""How the schema tests read a refusal: validate as the API does (a JSON body parsed, then
validated) and return the ``loc`` of each error, so a test names the field it expects refused."""

from __future__ import annotations

import pytest
from pydantic import TypeAdapter, ValidationError

LEG = {"psi0_deg": 30.0, "zeta0": 0.9}  # a valid leg: the paper's period-1 gait
START = {"xdot": -0.93, "ydot": -0.17}  # a valid section state near it


def accepted(schema, data):
    """``data`` validated as ``schema`` (a model, or an annotated union such as ``JobCreate``)."""
    return TypeAdapter(schema).validate_python(data)


def refused(schema, data) -> list[tuple]:
    """The ``loc`` of every error refusing ``data`` as ``schema``; fails the test if it is accepted."""
    with pytest.raises(ValidationError) as refusal:
        TypeAdapter(schema).validate_python(data)
    return [error["loc"] for error in refusal.value.errors()]


def refusal_messages(schema, data) -> str:
    """Every error's message refusing ``data`` as ``schema``, joined."""
    with pytest.raises(ValidationError) as refusal:
        TypeAdapter(schema).validate_python(data)
    return " | ".join(error["msg"] for error in refusal.value.errors())
