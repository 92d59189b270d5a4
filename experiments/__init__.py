"""Reproducible studies of the paper (issue 4): one file per figure, each a Config, run, plot, claims."""
