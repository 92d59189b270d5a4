"""Who a request comes from: its bearer token, looked up among the lab's people.

A request names its person with ``Authorization: Bearer <token>``: the service's own token
(``api_token``) is :data:`~backend.store.people.LAB`'s, the tokens ``parkour token add`` makes
are the people's (:mod:`backend.store.people`). :class:`~backend.api.security.TokenFirst` finds the
person once per request and leaves them in the request's state; routes read them with
:func:`person_of`, and what they store says who (a job's ``submitted_by``, a run's ``created_by``,
an e-stop's ``pressed_by`` ...).

A browser's event streams and websockets cannot send a header, so where reads need a token (a
service listening beyond this machine) the panel's sign-in check (``GET /api/v1/auth``) also leaves
the token in a cookie (:data:`READ_COOKIE`: HttpOnly, SameSite=Strict, the API's path only). The
cookie is taken for reads alone, never for a change: a page on another site cannot make the
browser change anything with it.
"""

from __future__ import annotations

import secrets

from starlette.datastructures import Headers
from starlette.requests import HTTPConnection
from starlette.types import Scope

from backend.store.people import LAB, PeopleFile, Person

READ_COOKIE = "parkour_token"
SAFE_METHODS = frozenset({"GET", "HEAD", "OPTIONS"})


def bearer_token(authorization: str | None) -> str | None:
    """The token of an ``Authorization: Bearer <token>`` header, or None."""
    scheme, _, credentials = (authorization or "").partition(" ")
    token = credentials.strip()
    return token if scheme.lower() == "bearer" and token else None


class Identities:
    """The people the service knows: its own token's (:data:`LAB`), then the people file's."""

    def __init__(self, lab_token: str, people: PeopleFile):
        self.lab_token, self.people = lab_token, people

    def who(self, token: str | None) -> Person | None:
        """The person ``token`` belongs to, or None (no token, or one nobody has)."""
        if not token:
            return None
        # compared in constant time, as bytes: a token that is not ASCII is a mismatch, not an error
        if secrets.compare_digest(token.encode("utf-8", "replace"), self.lab_token.encode()):
            return Person(LAB)
        return self.people.who(token)

    def of_scope(self, scope: Scope) -> tuple[Person | None, bool]:
        """Who a request or websocket comes from, and whether they said so by header (False: by the
        read cookie, or not at all). The cookie counts only for reads and websockets."""
        headers = Headers(scope=scope)
        by_header = self.who(bearer_token(headers.get("authorization")))
        if by_header is not None:
            return by_header, True
        if scope["type"] == "websocket" or scope.get("method") in SAFE_METHODS:
            return self.who(HTTPConnection(scope).cookies.get(READ_COOKIE)), False
        return None, False


def person_of(connection: HTTPConnection) -> Person | None:
    """The person :class:`~backend.api.security.TokenFirst` found for this request (None: nobody
    signed in, as on the e-stop with no token)."""
    return connection.scope.get("state", {}).get("person")


def signed_in_by_header(connection: HTTPConnection) -> bool:
    """Whether :func:`person_of` came from the request's own ``Authorization`` header (False: from
    the read cookie, or nobody)."""
    return bool(connection.scope.get("state", {}).get("person_by_header"))


def who_label(connection: HTTPConnection) -> str:
    """Who did it, as a record keeps it: the person's name, else the client's address (an
    e-stop needs no token: ``someone at 127.0.0.1``)."""
    person = person_of(connection)
    if person is not None:
        return person.name
    address = connection.client.host if connection.client is not None else "an unknown address"
    return f"someone at {address}"
