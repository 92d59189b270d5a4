"""The people file (backend/store/people.py): names and token hashes, changed under a lock, written
whole, looked up again whenever it changed."""

from __future__ import annotations

import json
import stat
import threading

import pytest

from backend.store.people import LAB, Access, PeopleError, PeopleFile, Person, token_digest


def test_a_token_signs_in_its_person_and_only_its_hash_is_kept(tmp_path):
    people = PeopleFile(tmp_path)
    ada, dash = people.add("ada"), people.add("dash", Access.READ)
    assert people.who(ada) == Person("ada", Access.WRITE) and people.who(dash) == Person("dash", Access.READ)
    assert people.who("nobody's token") is None and people.who(ada + "x") is None
    text = people.path.read_text()
    assert ada not in text and dash not in text and token_digest(ada) in text
    assert stat.S_IMODE(people.path.stat().st_mode) == 0o600
    assert [entry.name for entry in people.entries()] == ["ada", "dash"]


def test_names_are_checked_and_a_name_has_one_token(tmp_path):
    people = PeopleFile(tmp_path)
    people.add("ada")
    for bad in ("", "1ada", "a b", "a" * 33, "<b>", LAB):
        with pytest.raises(PeopleError):
            people.add(bad)
    with pytest.raises(PeopleError, match="has a token already"):
        people.add("ada")
    with pytest.raises(PeopleError, match="nobody named 'bob'"):
        people.revoke("bob")
    assert [entry.name for entry in people.entries()] == ["ada"]


def test_another_process_revoking_is_seen_at_the_next_look_up(tmp_path):
    service, command = PeopleFile(tmp_path), PeopleFile(tmp_path)  # the service's and parkour token's
    token = command.add("ada")
    assert service.who(token) == Person("ada")
    command.revoke("ada")
    assert service.who(token) is None
    again = command.add("ada")
    assert service.who(again) == Person("ada") and service.who(token) is None


def test_changes_at_once_all_land(tmp_path):
    names = [f"p{index}" for index in range(16)]
    threads = [threading.Thread(target=PeopleFile(tmp_path).add, args=(name,)) for name in names]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert sorted(entry.name for entry in PeopleFile(tmp_path).entries()) == sorted(names)


def test_a_corrupt_file_signs_nobody_in_and_says_so_to_a_change(tmp_path):
    people = PeopleFile(tmp_path)
    token = people.add("ada")
    people.path.write_text("{not json")
    assert people.who(token) is None
    with pytest.raises(PeopleError, match="cannot be read"):
        people.add("bob")
    people.path.write_text(json.dumps({"people": [{"name": "ada"}]}))
    with pytest.raises(PeopleError, match="not as written by parkour token"):
        people.entries()
