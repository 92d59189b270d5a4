"""``python -m cli``: the ``parkour`` command."""

from cli.app import main

main()
