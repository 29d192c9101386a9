"""Regenerate docs/figures/: one example of every figure kind `gcalign plot` draws, from
the commands themselves (the built-in scenarios, the configs and the real recording).

    python docs/make_figures.py            # about a minute on one core

Every figure is written exactly as ``gcalign plot`` writes it (:func:`plot_file`), then
renamed after what it shows. tests/test_plots.py checks the axes and series of each kind
on small runs; this script is for the documentation (README, docs/batch.md, docs/results*).
The realtime figures are also made by docs/results_realtime.py, the calibrate and
observability ones by docs/make_results_calibrate.py, and the T_z sweep figure
``seed000_tz.png`` and the box plot per mode ``batch_error_t3_deg.png`` by
docs/seed000_results.py (from the full sweeps; here a small one,
``batch_error_t3_yaw_vs_t_z.png``).
"""

from __future__ import annotations

import shutil
import sys
import tempfile
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "docs" / "figures"
REAL = ROOT / "tests" / "data" / "lasergyro.imu.xz"


def _cli(*args: str) -> None:
    from typer.testing import CliRunner

    from gcalign.cli import app

    res = CliRunner().invoke(app, [str(a) for a in args])
    if res.exit_code != 0:
        sys.exit(f"gcalign {' '.join(map(str, args))}: exit {res.exit_code}\n{res.output}")


def _plot(results: Path, names: dict[str, str], tmp: Path) -> list[Path]:
    """Plot a results (or data) file and copy its figures `names` (stem -> docs name)."""
    from gcalign.app.readback import plot_file

    written = {p.stem: p for p in plot_file(results, tmp / f"{results.name}_plots")}
    out = []
    for stem, name in names.items():
        target = OUT / f"{name}.png"
        shutil.copyfile(written[stem], target)
        out.append(target)
    return out


def _small_batch(tmp: Path) -> Path:
    """A small sweep of the built-in alignment: three modes × three T_z × 6 seeds."""
    sweep = tmp / "modes.yaml"
    sweep.write_text(yaml.safe_dump({
        "name": "modes-tz", "base": str(ROOT / "configs" / "seed000_moving_full_cycle.yaml"),
        "grid": {"align.mode": ["conventional", "full-cycle", "half-cycle"],
                 "align.stages.0.t_z_s": [100, 200, 300]},
        "seeds": 6, "metrics": ["error_t3_deg.2"]}))
    out = tmp / "modes-tz.h5"
    _cli("batch", sweep, "--workers", 1, "-o", out)
    return out


def main() -> list[Path]:
    OUT.mkdir(parents=True, exist_ok=True)
    made: list[Path] = []
    with tempfile.TemporaryDirectory() as folder:
        tmp = Path(folder)
        moving = ROOT / "configs" / "seed000_moving_full_cycle.yaml"
        _cli("align", "-o", tmp / "align.h5")
        made += _plot(tmp / "align.h5", {"align_error": "align_error",
                                          "align_attitude": "align_attitude"}, tmp)
        _cli("align", ROOT / "configs" / "lasergyro_align.yaml", "-o", tmp / "real.h5")
        made += _plot(tmp / "real.h5", {"align_attitude": "align_attitude_lasergyro"}, tmp)
        _cli("navigate", REAL, "--init", tmp / "real.h5", "-o", tmp / "real-nav.h5")
        made += _plot(tmp / "real-nav.h5", {"navigate": "navigate_lasergyro"}, tmp)
        made += _plot(REAL, {"imu": "imu_lasergyro"}, tmp)
        _cli("navigate", moving, "-o", tmp / "nav.h5")
        made += _plot(tmp / "nav.h5", {"navigate_error": "navigate_error"}, tmp)
        _cli("simulate", moving, "-o", tmp / "sim.h5")
        made += _plot(tmp / "sim.h5", {"truth": "truth", "imu": "imu"}, tmp)
        _cli("northfind", "-o", tmp / "nf.h5")
        made += _plot(tmp / "nf.h5", {"northfind_error": "northfind_error",
                                       "northfind_difference": "northfind_difference"}, tmp)
        _cli("realtime", "-o", tmp / "rt.h5")
        made += _plot(tmp / "rt.h5", {"realtime_case11": "realtime_case11",
                                       "realtime_filter": "realtime_filter",
                                       "realtime_lag": "realtime_lag"}, tmp)
        _cli("calibrate", "-o", tmp / "cal.h5")
        made += _plot(tmp / "cal.h5", {k: f"calibrate_{k}" for k in (
            "trajectory", "sensor_biases", "scale_factors", "sigma", "navigation_errors",
            "innovations")}, tmp)
        _cli("calibrate", ROOT / "configs" / "lasergyro_calibrate.yaml", "-o", tmp / "zv.h5")
        made += _plot(tmp / "zv.h5", {"attitude": "calibrate_lasergyro_attitude"}, tmp)
        _cli("observability", "-o", tmp / "obs.h5")
        made += _plot(tmp / "obs.h5", {"observability_segments": "observability_segments",
                                        "observability_cumulative": "observability_cumulative",
                                        "covariance_degree": "observability_covariance_degree"},
                      tmp)
        made += _plot(_small_batch(tmp), {
            "batch_error_t3_deg_2_vs_t_z_s": "batch_error_t3_yaw_vs_t_z"}, tmp)
    return made


if __name__ == "__main__":
    for p in main():
        print(p.relative_to(ROOT))
