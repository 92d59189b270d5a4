"""ParkourLab's service side: the FastAPI service, its store, and the robot link.

- :mod:`backend.api` — the REST API (``/api/v1``), thin routes over the services;
- :mod:`backend.services` — what the service does: simulations, stored runs and experiments,
  batch jobs, live robot runs, and the interface of the 3D view;
- :mod:`backend.store` — SQLAlchemy models, the database engine, Alembic migrations;
- :mod:`backend.robot` — the radio protocol, the PC's link, tracker input, touchdown detection,
  and the virtual robot;
- :mod:`backend.schemas` (request and response bodies), :mod:`backend.settings`.

The ``parkour`` command line sits above this package, in ``cli/``.
"""
