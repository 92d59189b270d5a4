"""Alembic environment: runs migrations on the engine handed over by ``backend.store.database``."""

from alembic import context

from backend.store.models import Base, modelled

config = context.config
engine = config.attributes["engine"]

with engine.begin() as connection:
    context.configure(
        connection=connection,
        target_metadata=Base.metadata,
        include_object=modelled,  # the search index is the migrations' alone
        render_as_batch=engine.dialect.name == "sqlite",  # SQLite alters tables by copying them
    )
    with context.begin_transaction():
        context.run_migrations()
