"""The REST API (``/api/v1``): thin routes that translate HTTP to calls of ``backend.services``."""
