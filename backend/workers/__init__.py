"""Where the service's compute and its heaviest reads run: worker processes, never the service's own.

- :mod:`.pools` — :class:`~.pools.ComputePool` (a few ``spawn`` processes, bounded in calls
  waiting and in time) and :class:`~.pools.Compute`, the service's three pools;
- :mod:`.parent` — the watch that ends a worker once the service that started it is gone;
- :mod:`.progress` — :func:`~.progress.report`, how a call in a worker says how far it has got;
- :mod:`.store_reads` — the run list's pages and exports, read and encoded in the reads pool.

The workers are handed what they run: the functions they call, their warm-up and the store reads
come from the caller (``create_app`` assembles them), so this package imports nothing from
``backend.services`` or ``backend.api`` — the services import it, never the other way round.
"""
