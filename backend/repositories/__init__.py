"""SQL and only SQL, one module per aggregate; the shared paging and locking helpers in :mod:`.common`.

Services own the unit of work (the session and its commit) and call these; nothing outside
``backend.store`` and ``backend.repositories`` builds SQLAlchemy statements.
"""
