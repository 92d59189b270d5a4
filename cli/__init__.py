"""The ``parkour`` command: the top layer, above the service and the 3D view.

One typer sub-app per command file (``simulate``: map and trajectory; ``gaits``: fixed-point and
gaits; ``basin``, ``sweep``, ``mjtf``, ``pid``, ``atlas``, ``reproduce``, ``robot``: robot-sim;
``bench``, ``serve``), each a thin layer over one library call; :mod:`cli.app` assembles them,
:mod:`cli.options` holds what they share and :mod:`cli.studies` how the studies run. Command
modules import only typer and the option types at load time and the numerical core, the store
or the service inside the command, so ``parkour --help`` starts at once.
"""
