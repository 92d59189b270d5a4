"""Robustness under noise: Mean Jumps To Failure by Monte-Carlo (:mod:`.mjtf`), the mean first passage time
of the noisy map's Markov chain (:mod:`.mfpt`) and rare-event splitting for closed loops (:mod:`.splitting`)
(docs/analyses.md).
"""
