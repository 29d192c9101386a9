"""Commands as the user runs them: one folder per capability (its run, summary, results-file
writer, table and figures) whose ``__init__`` holds its command object
(:class:`~gcalign.app.command.Command`: check, cost, execute, table, figures, layout), the
command registry (:mod:`~gcalign.app.registry`), the checks before a run
(:mod:`~gcalign.app.preflight`) and the batch engine (:mod:`~gcalign.app.batch`). The CLI is
a thin Typer layer over this package.
"""
