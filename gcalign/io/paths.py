"""What an input path is when it is not a regular file, for a one-line refusal."""

from __future__ import annotations

import errno
import os
import stat
from pathlib import Path


def not_a_file(path) -> str:
    """Why `path` cannot be read as a file: ``file not found``, ``is a FIFO (named pipe)``,
    ``is a symbolic link loop``, ``is a broken symbolic link to X``, ``is a directory``, ...
    (a FIFO would block the reader forever; a loop is not "missing")."""
    p = Path(path)
    try:
        st = p.stat()
    except OSError as err:
        if err.errno == errno.ELOOP:
            return "is a symbolic link loop, expected a file"
        if p.is_symlink():
            return f"is a broken symbolic link (to {os.readlink(p)}), expected a file"
        if err.errno == errno.ENOENT:
            return "file not found"
        return f"cannot be read ({err.strerror or err})"
    for test, what in ((stat.S_ISDIR, "a directory"), (stat.S_ISFIFO, "a FIFO (named pipe)"),
                       (stat.S_ISSOCK, "a socket"), (stat.S_ISCHR, "a character device"),
                       (stat.S_ISBLK, "a block device")):
        if test(st.st_mode):
            return f"is {what}, expected a regular file"
    return "file not found" if not stat.S_ISREG(st.st_mode) else "is a file"
