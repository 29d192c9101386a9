"""``python -m gcalign`` and the ``gcalign`` script: the command line (:mod:`gcalign.cli`).

A short command's start-up is largely Python's cyclic garbage collector walking, again and
again, the objects that importing typer, pydantic, numpy and numba creates (about 10^5, all
alive until the process ends): collection is paused while the command line is imported and
what the import made is then frozen (never walked again); :func:`gcalign.cli.main` freezes
what is alive at exit, so that the interpreter's finalisation does not walk it either.
Importing :mod:`gcalign.cli` as a library changes nothing of the collector.
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
