"""`gcalign northfind`: the pipeline, its summary, results file, table and figures."""
