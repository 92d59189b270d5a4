"""``parkour bench`` (cli/bench.py): the JSON contract."""

from tests.cli.helpers import json_of
from tests.sim_core.test_bench import CONTRACT as BENCH_CONTRACT


def test_bench_json_contract():
    sizes = ["--baseline-strides", "3", "--kernel-strides", "20", "--batch-strides", "20", "--repeats", "1"]
    payload = json_of("bench", *sizes, "--basin-grid", "4", "--basin-jumps", "5")
    assert set(payload) >= BENCH_CONTRACT
