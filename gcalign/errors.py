"""Errors that the command line turns into one line and an exit code, without a traceback."""


class GcalignError(Exception):
    """A failure the user can act on (exit code 1)."""

    exit_code = 1


class ScenarioError(GcalignError, ValueError):
    """Bad input: a scenario, option or input file that cannot be used (exit code 2).

    The message names the field, the value received and what is allowed.
    """

    exit_code = 2
