"""``parkour token add|list|revoke`` (cli/token.py): the --json contract, errors as one line, and
tokens that the people file (and so the service) knows at once."""

from __future__ import annotations

import json

from backend.store.people import Access, PeopleFile, Person
from tests.cli.helpers import invoke


def test_add_prints_the_contract_and_the_token_signs_its_person_in(tmp_path):
    result = invoke("token", "add", "ada", "--data-dir", str(tmp_path), "--json")
    assert result.exit_code == 0, result.output
    printed = json.loads(result.stdout)
    assert set(printed) == {"name", "token", "sign_in_url"} and printed["name"] == "ada"
    assert printed["sign_in_url"] == f"http://127.0.0.1:8000/panel/#token={printed['token']}"
    assert PeopleFile(tmp_path).who(printed["token"]) == Person("ada", Access.WRITE)
    reader = json.loads(invoke("token", "add", "dash", "--read-only", "--url", "http://lab-pc:9000/",
                               "--data-dir", str(tmp_path), "--json").stdout)  # fmt: skip
    assert reader["sign_in_url"].startswith("http://lab-pc:9000/panel/#token=")
    assert PeopleFile(tmp_path).who(reader["token"]) == Person("dash", Access.READ)


def test_list_and_revoke(tmp_path):
    for name in ("ada", "bob"):
        invoke("token", "add", name, "--data-dir", str(tmp_path))
    listed = json.loads(invoke("token", "list", "--data-dir", str(tmp_path), "--json").stdout)
    assert [(row["name"], row["access"]) for row in listed] == [("ada", "write"), ("bob", "write")]
    assert "token" not in json.dumps(listed), "never the tokens"
    revoked = invoke("token", "revoke", "bob", "--data-dir", str(tmp_path), "--json")
    assert json.loads(revoked.stdout) == {"name": "bob", "revoked": True}
    assert [entry.name for entry in PeopleFile(tmp_path).entries()] == ["ada"]


def test_mistakes_are_one_line_and_exit_2(tmp_path):
    invoke("token", "add", "ada", "--data-dir", str(tmp_path))
    for args, said in (
        (("add", "ada"), "ada has a token already"),
        (("add", "lab"), "taken by the service's own token"),
        (("add", "a b"), "is not allowed: 1 to 32 characters"),
        (("revoke", "bob"), "nobody named 'bob'"),
    ):
        result = invoke("token", *args, "--data-dir", str(tmp_path))
        assert result.exit_code == 2 and result.stderr.startswith("error: ") and said in result.stderr, args
        assert len(result.stderr.strip().splitlines()) == 1, result.stderr
