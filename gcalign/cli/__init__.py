"""The `gcalign` command line (Typer). It only translates: load the scenario, call a
pipeline, write the results file, render a table or JSON.

Exit codes: 0 success, 2 bad input (one line naming the field, the value and what is
allowed), 1 other failures, 130 interrupted (Ctrl-C), 143 terminated (SIGTERM); every
failure is one line on stderr and never a traceback (``GCALIGN_TRACEBACK=1`` shows the
traceback of an unexpected error, which is a bug).
"""

# First, before anything loads NumPy: its OpenBLAS under an address-space limit
from gcalign.cli import address_space  # noqa: F401

# isort: split
from gcalign.cli.base import _terminate, app, consoles, emit_json, main, user_errors

__all__ = ["_terminate", "app", "consoles", "emit_json", "main", "user_errors"]

# Commands register themselves on `app`.
from gcalign.cli import align as _align  # noqa: E402,F401
from gcalign.cli import allan as _allan  # noqa: E402,F401
from gcalign.cli import batch as _batch  # noqa: E402,F401
from gcalign.cli import calibrate as _calibrate  # noqa: E402,F401
from gcalign.cli import data as _data  # noqa: E402,F401
from gcalign.cli import example as _example  # noqa: E402,F401
from gcalign.cli import export as _export  # noqa: E402,F401
from gcalign.cli import modulate as _modulate  # noqa: E402,F401
from gcalign.cli import northfind as _northfind  # noqa: E402,F401
from gcalign.cli import plot as _plot  # noqa: E402,F401
from gcalign.cli import realtime as _realtime  # noqa: E402,F401

# Last: the options every scenario command shares (--set, --imu-file, --lat/--lon/--height).
from gcalign.cli.common import install as _install  # noqa: E402

_install(app)
