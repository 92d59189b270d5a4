"""Stored calibrations' SQL (backend/repositories/calibrations.py) on a migrated SQLite file."""

import pytest

from backend.errors import Conflict, NotFound
from backend.repositories import calibrations as stored
from backend.store.models import ModelPreset


def _preset(name: str) -> ModelPreset:
    return ModelPreset(name=name, base="paper", physical={}, offsets={}, fit={}, runs=[1], code_version="test")


def test_presets_by_name_in_order_and_deleted(sessions):
    with sessions() as session:
        for name in ("b", "a"):
            stored.add(session, _preset(name))
        session.commit()
        assert [preset.name for preset in stored.all_presets(session)] == ["b", "a"], "oldest first"
        assert stored.named(session, "a").name == "a" and stored.named(session, "c") is None
        assert stored.exists(session, "b") and not stored.exists(session, "c")
        stored.delete(session, "b")
        session.commit()
        assert [preset.name for preset in stored.all_presets(session)] == ["a"]
        with pytest.raises(NotFound, match="preset b"):
            stored.get(session, "b")
        with pytest.raises(NotFound):
            stored.delete(session, "b")


def test_a_name_stored_meanwhile_is_a_conflict(sessions):
    with sessions() as first, sessions() as second:
        assert not first.get(ModelPreset, 1)  # the first has read: its check saw no such name
        stored.add(second, _preset("same"))
        second.commit()
        with pytest.raises(Conflict, match="'same' exists"):
            stored.add(first, _preset("same"))
    with sessions() as session:
        assert [preset.name for preset in stored.all_presets(session)] == ["same"]
