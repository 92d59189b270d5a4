"""What the service does, independent of HTTP: simulations (``simulation``), stored runs and
experiments (``runs``, ``experiments``; their SQL in :mod:`backend.repositories`), batch jobs
(``jobs``), live runs on the robot (``robot``), and the interface the 3D view implements (``view``)."""
