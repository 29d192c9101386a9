"""``python -m gcalign``: the command line, as the ``gcalign`` script runs it."""

from gcalign.cli import main

if __name__ == "__main__":
    main()
