"""What every command's bad-input test checks (DESIGN.md "CLI": exit 2, one line naming the
field, no traceback, no results file)."""

from __future__ import annotations

from pathlib import Path


def assert_bad_input(res, out: Path, field: str, *more: str) -> None:
    assert res.exit_code == 2, res.output
    assert "Traceback" not in res.output
    lines = [ln for ln in res.output.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("error: "), res.output
    assert field in lines[0], res.output
    for text in more:
        assert text in lines[0], res.output
    assert not out.exists()


def assert_bad_run(run, folder: Path, args, field: str, *more: str) -> None:
    """`run(*args, "-o", OUT)` is bad input (:func:`assert_bad_input`) and leaves no new file
    in `folder`, no temporary file either."""
    out = folder / "out.h5"
    before = set(folder.iterdir())
    res = run(*args, "-o", str(out))
    assert_bad_input(res, out, field, *more)
    assert set(folder.iterdir()) == before
