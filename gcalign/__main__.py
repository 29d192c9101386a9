"""``python -m gcalign`` and the ``gcalign`` script: the command line (:mod:`gcalign.cli`).

About a quarter of a short command's CPU went to Python's cyclic garbage collector walking,
again and again, the objects that importing typer, pydantic, numpy and numba creates (about
10^5, all alive until the process ends), and walking them once more in the interpreter's
finalisation. Here collection is paused while the command line is imported and what the
import made is then frozen (never walked again); a command does the same while it loads
the scenario models and its kernels (:func:`gcalign.app.command.loading`), and
:func:`gcalign.cli.main` freezes what is alive at exit. Importing :mod:`gcalign.cli` as a
library changes nothing of the collector.
"""

import gc


def main() -> None:
    """The ``gcalign`` command line."""
    gc.disable()
    try:
        from gcalign.cli import main as cli_main
    finally:
        gc.freeze()
        gc.enable()
    cli_main()


if __name__ == "__main__":
    main()
