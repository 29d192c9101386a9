"""Shared fixtures. The real recording ships with the repository (tests/data/, xz), so no
real-data test skips in a plain clone."""

from __future__ import annotations

import lzma
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
#: The PSINS lasergyro.imu recording, compressed (tests/data/README.md).
LASERGYRO_XZ = ROOT / "tests" / "data" / "lasergyro.imu.xz"


@pytest.fixture(scope="session")
def lasergyro(tmp_path_factory) -> Path:
    """The plain lasergyro.imu (decompressed once per test session), for the readers and
    for anything that needs the file itself."""
    path = tmp_path_factory.mktemp("data") / "lasergyro.imu"
    path.write_bytes(lzma.decompress(LASERGYRO_XZ.read_bytes()))
    return path
