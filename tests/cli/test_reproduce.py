"""``parkour reproduce`` (cli/reproduce.py): the figures' files listed as JSON, and a figure name
that is not one named on stderr. What reproduction writes is tested in
tests/experiments/test_reproduce.py."""

import json

from tests.cli.helpers import invoke


def test_reproduce_cli(tmp_path):
    result = invoke("reproduce", "fig12", "--quick", "--out", str(tmp_path), "--json")
    assert result.exit_code == 0, result.output
    payload = json.loads(result.stdout)
    assert payload["figures"] == ["fig12"] and str(tmp_path / "report.md") in payload["files"]
    bad = invoke("reproduce", "fig13", "--out", str(tmp_path))
    assert bad.exit_code == 2 and bad.stderr.startswith("error: figure:")


def test_without_json_it_lists_the_files_written_and_points_at_the_report(tmp_path):
    result = invoke("reproduce", "fig12", "fig12", "--quick", "--out", str(tmp_path))
    assert result.exit_code == 0, result.output
    listed = result.stdout.splitlines()
    names = ("fig12.png", "fig12.svg", "fig12.csv", "fig12.json", "report.md")
    assert listed == [str(tmp_path / name) for name in names], "once each, though named twice"
    assert f"report: {tmp_path / 'report.md'}" in result.stderr
