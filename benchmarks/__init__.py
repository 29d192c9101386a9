"""Benchmarks of gcalign: each ``bench_*.py`` is a script that prints its figures (medians,
contenders interleaved) against its targets; ``python -m benchmarks`` runs them."""
