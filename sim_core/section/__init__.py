"""The section's gaits: fixed points of the Poincaré map and their stability, the gait search, the gait atlas
(docs/model.md §5, docs/analyses.md).
"""
