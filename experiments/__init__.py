"""Reproducible studies of the paper: one module per figure (a Config, run, plot, claims),
``reproduce`` to write them with their data and a report, and ``cluster`` to run big studies
on Dask."""
