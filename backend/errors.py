"""The backend's domain errors: what a service or repository raises that a client can act on.

The API maps each to its status in one table (:mod:`backend.api.errors`); the CLI prints them.
"""

from __future__ import annotations


class NotFound(LookupError):
    """No record of that kind with that id."""

    def __init__(self, what: str, identifier: int):
        super().__init__(f"{what} {identifier} does not exist")
        self.what, self.identifier = what, identifier

    def __reduce__(self):  # picklable as made: the store is read in worker processes too
        return type(self), (self.what, self.identifier)


class Conflict(RuntimeError):
    """The request contradicts stored data (e.g. deleting an experiment that still has runs)."""


class QueueFull(RuntimeError):
    """The job queue holds its budget of work (or this client its share); the message says how much
    is queued and what to do."""
