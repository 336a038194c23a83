"""Presentation: what a person reads (text summaries, the HTML report, pictures) and the story jobs.

Modules
-------
text    one-screen text summaries of every result (what the commands print)
html    the self-contained HTML report: sections rendered from result values
plots   PNG pictures of results (the Allan deviation with its band, fit and plan; the segmentation of a
        rate-table log)
story   the report job (every job whose inputs are given) and the demo on bundled inputs

Functions here take result values (``align.results.Result`` types) and return
text or bytes; they never write files (the command line commits its outputs).
"""
