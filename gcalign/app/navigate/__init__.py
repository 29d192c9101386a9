"""`gcalign navigate`: the pipeline, its summary, results file, table and figures."""
