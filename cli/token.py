"""``parkour token add|list|revoke``: the lab's people and their API tokens.

Each person gets a token of their own, so what they do is recorded under their name (a job's
``submitted_by``, a run's ``created_by``, an e-stop's ``pressed_by`` ...) and the job queue's
shares are theirs. The tokens live in the data directory's ``people.json`` (only their hashes);
these commands work while the service runs, and a revoked token is refused at its next request.
"""

from __future__ import annotations

import json
import os
from typing import Annotated

import typer

from cli.options import EXIT_USAGE, DataDirOption, JsonOption

app = typer.Typer(name="token", help="Give people API tokens of their own, list them, revoke them.",
                  no_args_is_help=True, rich_markup_mode=None)  # fmt: skip
DEFAULT_URL = "http://127.0.0.1:8000"
NameArgument = Annotated[str, typer.Argument(help="The person's name, as records will show it (e.g. ada).")]


def _people(data_dir):
    from backend.settings import Settings
    from backend.store.people import PeopleFile

    return PeopleFile(Settings.from_environment(data_dir).data_dir)


def _fail(error: Exception) -> None:
    typer.echo(f"error: {error}", err=True)
    raise typer.Exit(EXIT_USAGE) from None


@app.command("add")
def add_command(
    name: NameArgument,
    data_dir: DataDirOption = None,
    read_only: Annotated[
        bool, typer.Option("--read-only", help="A token that reads but changes nothing (e.g. for a dashboard).")
    ] = False,
    url: Annotated[
        str | None,
        typer.Option("--url", help=f"The service's address for the sign-in link (default $PARKOUR_URL, {DEFAULT_URL})"),
    ] = None,
    as_json: JsonOption = False,
) -> None:
    """Make NAME a token and print it with a sign-in link (shown once: only its hash is kept)."""
    from backend.store.people import Access, PeopleError

    try:
        token = _people(data_dir).add(name, Access.READ if read_only else Access.WRITE)
    except (PeopleError, OSError) as error:
        _fail(error)
    base = (url or os.environ.get("PARKOUR_URL") or DEFAULT_URL).rstrip("/")
    # The token rides in the fragment, which a browser never sends to a server: it is in no log.
    sign_in_url = f"{base}/panel/#token={token}"
    if as_json:
        typer.echo(json.dumps({"name": name, "token": token, "sign_in_url": sign_in_url}))
        return
    typer.echo(f"token for {name} ({'read-only' if read_only else 'reads and changes'}): {token}")
    typer.echo(f"sign-in link (opens the panel signed in as {name}): {sign_in_url}")
    typer.echo("It is shown only now: give it to them; parkour token revoke NAME withdraws it.")


@app.command("list")
def list_command(data_dir: DataDirOption = None, as_json: JsonOption = False) -> None:
    """Everyone with a token: name, access, when it was made (never the tokens)."""
    from backend.store.people import PeopleError

    try:
        entries = _people(data_dir).entries()
    except (PeopleError, OSError) as error:
        _fail(error)
    rows = [{"name": entry.name, "access": entry.access.value, "created_at": entry.created_at} for entry in entries]
    if as_json:
        typer.echo(json.dumps(rows))
        return
    if not rows:
        typer.echo("nobody has a token yet (the service's own, api_token, signs in as lab): parkour token add NAME")
    for row in rows:
        typer.echo(f"{row['name']:<32}  {row['access']:<5}  since {row['created_at']}")


@app.command("revoke")
def revoke_command(name: NameArgument, data_dir: DataDirOption = None, as_json: JsonOption = False) -> None:
    """Withdraw NAME's token: the service refuses it from its next request on."""
    from backend.store.people import PeopleError

    try:
        _people(data_dir).revoke(name)
    except (PeopleError, OSError) as error:
        _fail(error)
    typer.echo(json.dumps({"name": name, "revoked": True}) if as_json else f"revoked {name}'s token")
