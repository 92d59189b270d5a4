"""The experiment store: SQLAlchemy models, the database engine, and Alembic migrations.

Data flows parameters -> simulate -> analyse -> **store** -> show: the API and the job runner
write here; nothing is overwritten silently, and deleting is explicit.
"""
