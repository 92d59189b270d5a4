"""The ``parkour`` command: one typer sub-app per file, each a thin layer over one library call."""
