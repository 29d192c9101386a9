"""Small alignment scenarios shared by the CLI tests."""

from __future__ import annotations

from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[1]


def small_align(tmp_path: Path, **align) -> Path:
    """The built-in moving-base scenario, shortened: T2 = 60 s, 3 passes (fast); `align`
    keys replace the scenario's."""
    d = yaml.safe_load((ROOT / "configs/seed000_moving_full_cycle.yaml").read_text())
    d["motion"]["duration_s"] = 80
    d["align"]["stages"][0]["passes"] = 3
    d["align"].update({"t2_s": 60, "t3_s": 70, "level_s": 20, **align})
    p = tmp_path / "small.yaml"
    p.write_text(yaml.safe_dump(d))
    return p
