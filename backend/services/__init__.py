"""What the service does, independent of HTTP: runs, experiments, batch jobs."""
