"""Errors that the command line turns into one line and an exit code, without a traceback."""


def clip(text: str, n: int) -> str:
    """`text` cut to `n` characters, "..." marking the cut (a bad value echoed in a message
    can be megabytes long)."""
    return text if len(text) <= n else text[:n - 3] + "..."


class GcalignError(Exception):
    """A failure the user can act on (exit code 1)."""

    exit_code = 1


class Terminated(BaseException):
    """SIGTERM: unwinds like Ctrl-C, so that temporary files are removed."""


#: Set by the command line's SIGTERM handler before it raises: a raise that lands in a
#: finaliser or a weakref callback is printed as "Exception ignored" and lost, and the run
#: went on to write its file; the points that commit a result ask here (check_terminated).
TERMINATE_REQUESTED = [False]


def check_terminated() -> None:
    """Raise :class:`Terminated` if a SIGTERM arrived, even one whose exception was lost."""
    if TERMINATE_REQUESTED[0]:
        raise Terminated()


class ScenarioError(GcalignError, ValueError):
    """Bad input: a scenario, option or input file that cannot be used (exit code 2).

    The message names the field, the value received and what is allowed.
    """

    exit_code = 2


class InputError(ValueError):
    """An input a numerical function cannot use (arrays of the wrong shape, a time past
    the end of the data, ...); `field` names the argument or setting, `message` says what
    was received and what is allowed. Not a :class:`GcalignError`: the app turns it into
    a :class:`ScenarioError` naming the scenario's field."""

    def __init__(self, field: str, message: str):
        super().__init__(f"{field}: {message}")
        self.field = field
        self.message = message
