"""The ``parkour`` command: the top layer, above the service and the 3D view.

One typer sub-app per command file (``simulate``, ``gaits``, ``analyses``, ``reproduce``,
``robot``, ``bench``, ``serve``), each a thin layer over one library call; :mod:`cli.app`
assembles them. Command modules import only typer and the option types at load time and the
numerical core, the store or the service inside the command, so ``parkour --help`` starts at once.
"""
