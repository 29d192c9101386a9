"""Commands as the user runs them: one room per capability (its run, summary, results-file
writer, table and figures), the command registry (:mod:`~gcalign.app.registry`) and the
batch engine (:mod:`~gcalign.app.batch`). The CLI is a thin Typer layer over this package.
"""
