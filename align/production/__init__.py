"""A lot of units: the manifest, per-unit runs, the results table and the lot's statistics.

(Being built for issue 17.)
"""
