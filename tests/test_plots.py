"""`gcalign plot` and gcalign.app.plots: which figures, which axes, how many series, PNG files."""

from __future__ import annotations

import copy
import json
from pathlib import Path

import numpy as np
import pytest
import yaml
from lazy import lazy_module
from typer.testing import CliRunner

from gcalign.cli import app
from gcalign.io import results

plots = lazy_module("gcalign.app.plots")  # matplotlib: imported when a test runs
readback = lazy_module("gcalign.app.readback")

ROOT = Path(__file__).resolve().parents[1]
runner = CliRunner()
PNG = b"\x89PNG\r\n\x1a\n"

SMALL = {
    "name": "small-moving",
    "site": {"lat_deg": 45.7796, "lon_deg": 126.6705, "height_m": 0},
    "imu": {"gyro": {"bias_dph": [0.01, 0.01, 0.01], "arw_dprh": 0.001},
            "accel": {"bias_ug": [50, 50, 50], "vrw_ugrhz": 10}},
    "motion": {"kind": "moving", "attitude_deg": [0, 0, 30], "duration_s": 80,
               "segments": [{"duration_s": 10}, {"duration_s": 10, "accel_mps2": 1.0},
                            {"duration_s": 10, "rate_dps": [0, 0, -1]},
                            {"duration_s": 10, "rate_dps": [0, 0, 1]}, {"duration_s": 40}]},
    "align": {"mode": "full-cycle", "t1_s": 10, "t2_s": 60, "t3_s": 70, "stages": [{"passes": 3}],
              "level_s": 20, "aiding": {"source": "odometer", "noise_mps": 0.01}},
}


def data_series(ax) -> list:
    """Lines that are data (guides such as pass boundaries are labelled '_...')."""
    return [ln for ln in ax.lines if not ln.get_label().startswith("_")]


def boundaries(ax) -> list:
    return [ln for ln in ax.lines if ln.get_label() == "_pass boundary"]


@pytest.fixture(scope="module")
def align_files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("align")
    out = {}
    for mode in ("full-cycle", "conventional"):
        d = copy.deepcopy(SMALL)
        d["align"]["mode"] = mode
        sc = folder / f"{mode}.yaml"
        sc.write_text(yaml.safe_dump(d))
        out[mode] = folder / f"{mode}.h5"
        res = runner.invoke(app, ["align", str(sc), "-o", str(out[mode])])
        assert res.exit_code == 0, res.output
    return out


def test_alignment_figures_per_pass_on_equivalent_time(align_files):
    """Rows pitch, roll, yaw; left all passes, right the zoom after pass 1; linear axes in
    the unit of the values; pass boundaries dotted; the legend below the panels."""
    figs = readback.figures_for(align_files["full-cycle"])
    assert set(figs) == {"align_error", "align_attitude"}
    err = figs["align_error"]
    assert len(err.axes) == 6
    full, zoom = err.axes[0::2], err.axes[1::2]
    assert full[0].get_title() == "all passes" and zoom[0].get_title() == "after pass 1 (zoom)"
    with results.open_results(align_files["full-cycle"]) as f:
        errors = [f[f"align/pass_{i:02d}/error"][()] for i in (1, 2, 3)]
    for j, name in enumerate(("pitch", "roll", "yaw")):
        for ax in (full[j], zoom[j]):
            assert ax.get_yscale() == "linear"
            assert ax.get_ylabel().startswith(f"{name} error (")
        assert len(data_series(full[j])) == 3  # one line per pass
        assert len(data_series(zoom[j])) == 2  # passes 2 and 3
        assert len(boundaries(full[j])) == 2  # between passes 1|2 and 2|3
        # Each panel's unit is the one its values need (deg from 1°, ′ from 1′, else ″).
        for ax, values in ((full[j], np.concatenate([e[:, j] for e in errors])),
                           (zoom[j], np.concatenate([e[:, j] for e in errors[1:]]))):
            unit = ax.get_ylabel().split("(")[1].rstrip(")")
            assert unit == plots.angle_scale(values)[1]
            scale = plots.angle_scale(values)[0]
            drawn = np.concatenate([ln.get_ydata() for ln in data_series(ax)])
            np.testing.assert_allclose(drawn, values * scale)
    assert "equivalent time (s)" in full[-1].get_xlabel()
    # Passes laid end to end: 10 s + 3 × 50 s of fine-alignment data.
    lines = data_series(full[2])
    np.testing.assert_allclose([ln.get_xdata()[0] for ln in lines], [10, 60, 110])
    np.testing.assert_allclose(lines[-1].get_xdata()[-1], 160)
    np.testing.assert_allclose([b.get_xdata()[0] for b in boundaries(full[0])], [60, 110])
    assert [t.get_text() for t in err.legends[0].get_texts()] == [
        "pass 1 forward (stage 1)", "pass 2 reverse (stage 1)", "pass 3 forward (stage 1)"]
    att = figs["align_attitude"]
    assert len(att.axes) == 3
    for ax in att.axes:
        labels = [ln.get_label() for ln in data_series(ax)]
        assert len(labels) == 4 and labels[-1] == "truth"
        assert ax.get_ylabel().endswith("(deg)")
    assert not any(ax.get_legend() for ax in att.axes) and att.legends  # below, not on a panel
    assert att.get_suptitle().endswith("vs truth") and err.get_suptitle()


def test_conventional_has_one_pass_and_no_boundary(align_files):
    fig = readback.figures_for(align_files["conventional"])["align_error"]
    assert fig.axes[1].get_title() == "second half of the pass (zoom)"
    for ax in fig.axes:
        assert len(data_series(ax)) == 1 and not boundaries(ax)
    full, zoom = data_series(fig.axes[4])[0], data_series(fig.axes[5])[0]
    n = len(full.get_xdata())
    np.testing.assert_allclose(zoom.get_xdata(), full.get_xdata()[n // 2:])
    # one pass: its data time, with no word of passes laid end to end or their boundaries
    assert fig.axes[4].get_xlabel() == fig.axes[5].get_xlabel() == "time (s)"


def test_alignment_of_recorded_data_has_no_truth_in_its_figures(tmp_path):
    """The real file: the attitude figure alone, titled as having no truth."""
    out = tmp_path / "real.h5"
    res = runner.invoke(app, ["align", str(ROOT / "configs/lasergyro_align.yaml"), "-o",
                              str(out), "--set", "align.t2_s=150", "--set", "align.t3_s=150"])
    assert res.exit_code == 0, res.output
    figs = readback.figures_for(out)
    assert set(figs) == {"align_attitude"}
    fig = figs["align_attitude"]
    assert "no truth" in fig.get_suptitle() and "vs truth" not in fig.get_suptitle()
    assert [ln.get_label() for ln in data_series(fig.axes[2])] == ["pass 1 forward (stage 1)"]
    assert fig.axes[-1].get_xlabel() == "time (s)"  # one pass: no passes laid end to end
    assert "truth at T2" not in res.stdout and "estimate at T2 (deg)" in res.stdout
    assert "recorded data: no truth" in res.stdout


def _northfind_file(path: Path, repeats: int | None):
    """A results file with the /northfind layout only (methods' errors, true azimuths)."""
    az = np.radians(np.arange(0.0, 360.0, 30.0))
    rng = np.random.default_rng(1)
    with results.atomic_h5(path) as f:
        results.write_header(f, "northfind", "", 1, {"scenario": "synthetic"})
        g = f.create_group("northfind")
        g.attrs["methods"] = "coordinate,vector,none"
        results.put(g, "azimuth_true", az, "rad")
        for m, amp in (("coordinate", 0.0), ("vector", 0.0), ("none", 0.1)):
            shape = (repeats, az.size) if repeats else (az.size,)
            e = amp * np.sin(az) + 1e-4 * rng.standard_normal(shape)
            h = g.create_group(m)
            results.put(h, "error", e, "rad")
            results.put(h, "error_pred", amp * np.sin(az) if amp else np.full(az.size, np.nan),
                        "rad")


@pytest.mark.parametrize("repeats", [None, 7])
def test_northfind_figures_error_against_true_azimuth(tmp_path, repeats):
    path = tmp_path / "nf.h5"
    _northfind_file(path, repeats)
    figs = readback.figures_for(path)
    assert set(figs) == {"northfind_error", "northfind_difference"}
    fig = figs["northfind_error"]
    assert [ax.get_ylabel().split("\n")[0] for ax in fig.axes] == ["coordinate", "vector", "none"]
    # error, plus the closed form where there is one
    for ax, n in zip(fig.axes, (1, 1, 2), strict=True):
        assert len(data_series(ax)) == n
        assert len(ax.collections) == (1 if repeats else 0)  # ±1σ band over repeats
    np.testing.assert_allclose(data_series(fig.axes[0])[0].get_xdata(), np.arange(0, 360, 30))
    assert "true azimuth (deg" in fig.axes[-1].get_xlabel()
    diff = figs["northfind_difference"]
    ax = diff.axes[0]
    assert len(diff.axes) == 1 and ax.get_ylabel() == "difference (arcsec)"
    curve, seed = data_series(ax)  # the difference; the seed's ±1e-4° (dashed)
    assert seed.get_label() == "seed fig. 5 size: ±1e-4°"
    assert seed.get_ydata()[0] == pytest.approx(0.36)
    # coordinate and vector carry independent noise here: their difference is drawn
    with results.open_results(path) as f:
        d = np.degrees(f["northfind/coordinate/error"][()] - f["northfind/vector/error"][()])
    np.testing.assert_allclose(curve.get_ydata(), np.atleast_2d(d).mean(0) * 3600.0)
    assert ax.get_ylim()[1] >= 1.25 * np.abs(d * 3600.0).max() - 1e-12


def test_northfind_difference_at_round_off_is_drawn_as_zero():
    """Two methods that agree to round-off (1e-10″): a flat zero with the largest value in
    the label, and the axis spans the seed's ±1e-4° (no magnified noise)."""
    from gcalign.app.northfind.plots import northfind_difference_figure

    az = np.radians(np.arange(0.0, 360.0, 5.0))
    a = 1e-3 * np.sin(az)
    fig = northfind_difference_figure(az, a, a + 5e-16 * np.cos(az))
    ax = fig.axes[0]
    curve = data_series(ax)[0]
    assert not np.any(curve.get_ydata())
    assert "zero to round-off" in curve.get_label() and "1.0e-10″" in curve.get_label()
    assert ax.get_ylim() == pytest.approx((-0.54, 0.54))


def test_realtime_case_figure_reads_in_arcsec_without_an_offset():
    """A latched error of −288″ ± 0.03″ (20°/s × 4 ms) is labelled −288.0x″ on its axis, not
    ±0.0x with "−2.88e2" at the axis's end to be added to every label."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    from gcalign.app.realtime.plots import case_figure
    from gcalign.units import ARCSEC

    t = np.arange(0.0, 2.0, 1e-3)
    before = (-288.0 + 0.03 * np.sin(40.0 * t)) * ARCSEC
    fig = case_figure(t, t >= 0.5, before, {"taylor": before / 2880.0}, None,
                      component="yaw", reference="seed", title="rate 20°/s")
    FigureCanvasAgg(fig).draw()
    ax = fig.axes[0]
    assert ax.yaxis.get_offset_text().get_text() == ""
    ticks = [float(x.get_text().replace("−", "-")) for x in ax.get_yticklabels()]
    assert ticks and all(-288.05 < v < -287.95 for v in ticks)


def test_imu_figure_of_a_noise_free_sensor_reads_its_constant_output():
    """Earth rate to round-off (5.245 °/h ± 1e-10): the panel spans ±5 % about it, as
    matplotlib draws an exact constant, so its labels read °/h and no round-off offset."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    from gcalign.units import DPH

    t = np.arange(0.0, 10.0, 0.01)
    w = np.array([5.245, 9.085, 10.78]) * DPH * (1.0 + 1e-11 * np.sin(t))[:, None]
    fig = plots.imu_figure(t, w * 0.01, np.tile([0.0, 0.0, 0.0981], (len(t), 1)), 0.01)
    FigureCanvasAgg(fig).draw()
    for ax, value in zip(fig.axes[:3], (5.245, 9.085, 10.78), strict=True):
        assert ax.yaxis.get_offset_text().get_text() == ""
        assert ax.get_ylim() == pytest.approx((0.95 * value, 1.05 * value), rel=1e-6)


def test_northfind_figures_from_the_real_command(tmp_path):
    out = tmp_path / "nf.h5"
    res = runner.invoke(app, ["northfind", "-o", str(out)])
    assert res.exit_code == 0, res.output
    fig = readback.figures_for(out)["northfind_error"]
    with results.open_results(out) as f:
        methods = f["northfind"].attrs["methods"].split(",")
        m = f["northfind/azimuth_true"].shape[0]
    assert len(fig.axes) == len(methods)
    assert all(len(data_series(ax)[0].get_xdata()) == m for ax in fig.axes)


def _batch(folder: Path, name: str, **sweep) -> Path:
    (folder / f"{name}.yaml").write_text(yaml.safe_dump({
        "name": name, "base": copy.deepcopy(SMALL), "seeds": 3, **sweep}, sort_keys=False))
    out = folder / f"{name}.h5"
    res = runner.invoke(app, ["batch", str(folder / f"{name}.yaml"), "--workers", "1",
                              "-o", str(out)])
    assert res.exit_code == 0, res.output
    return out


@pytest.fixture(scope="module")
def batch_file(tmp_path_factory):
    """A categorical grid only: box plots."""
    return _batch(tmp_path_factory.mktemp("batch"), "b",
                  grid={"align.mode": ["conventional", "full-cycle"],
                        "align.compensation": ["none", "continued"]},
                  metrics=["error_t3_deg", "equivalent_s"])


@pytest.fixture(scope="module")
def sweep_file(tmp_path_factory):
    """Cases × a categorical × a numeric grid key: lines against the numeric key."""
    return _batch(tmp_path_factory.mktemp("sweep"), "s",
                  cases={"noisy": {}, "quiet": {"imu.gyro.arw_dprh": 0,
                                                "imu.accel.vrw_ugrhz": 0}},
                  grid={"align.mode": ["conventional", "full-cycle"],
                        "align.stages.0.t_z_s": [60, 40, 50]},
                  metrics=["error_t3_deg.2", "error_t3_deg"])


@pytest.mark.slow
def test_batch_figures_box_per_variant_and_component(batch_file):
    figs = readback.figures_for(batch_file)
    assert set(figs) == {"batch_error_t3_deg", "batch_equivalent_s"}
    fig = figs["batch_error_t3_deg"]
    assert len(fig.axes) == 3  # pitch, roll, yaw
    for ax, comp in zip(fig.axes, ("pitch", "roll", "yaw"), strict=True):
        assert len(ax.patches) == 4  # one box per variant
        unit = ax.get_ylabel().rsplit("(", 1)[1].rstrip(")")
        assert comp in ax.get_ylabel() and unit in ("deg", "arcmin", "arcsec")
    labels = [t.get_text() for t in fig.axes[-1].get_xticklabels()]  # shared x: bottom axes
    # one line per grid key, wrapped after '=' where a box is too narrow for it
    assert [t.replace("=\n", "=") for t in labels] == [
        "mode=conventional\ncompensation=none", "mode=conventional\ncompensation=continued",
        "mode=full-cycle\ncompensation=none", "mode=full-cycle\ncompensation=continued"]
    scalar = figs["batch_equivalent_s"]
    assert len(scalar.axes) == 1 and len(scalar.axes[0].patches) == 4
    assert scalar.axes[0].get_ylabel() == "equivalent_s (s)"


@pytest.mark.slow
def test_sweep_figure_median_against_the_numeric_key(sweep_file):
    """A numeric grid key gives lines instead of boxes: x = its values (sorted), y = the
    median over seeds of |metric| of each variant, read back from /batch/runs; one line
    per other grid value (mode), one column per case, one row per component."""
    figs = readback.figures_for(sweep_file)
    assert set(figs) == {"batch_error_t3_deg_2_vs_t_z_s", "batch_error_t3_deg_vs_t_z_s"}
    with results.open_results(sweep_file) as f:
        r = f["batch/runs"]
        variant, yaw = r["variant"][()], r["metrics"]["error_t3_deg.2"][()]
        summary = json.loads(f.attrs["summary_json"])
    expected: dict[tuple[str, str], dict[float, float]] = {}
    for v in summary["variants"]:
        o = v["overrides"]
        key = (o["case"], o["align.mode"])
        expected.setdefault(key, {})[o["align.stages.0.t_z_s"]] = float(
            np.median(np.abs(yaw[variant == v["index"]])))
    # the unit the row's largest |yaw| needs (deg from 1°, arcmin from 1′, else arcsec)
    top = float(np.max(np.abs(yaw[np.isfinite(yaw)])))
    unit, factor = (("deg", 1.0) if top >= 1 else ("arcmin", 60.0) if top * 60 >= 1
                    else ("arcsec", 3600.0))
    fig = figs["batch_error_t3_deg_2_vs_t_z_s"]
    assert len(fig.axes) == 2  # one row (a scalar metric) × two cases
    for ax, case in zip(fig.axes, ("noisy", "quiet"), strict=True):
        assert ax.get_title() == f"case: {case}"
        lines = data_series(ax)
        assert [ln.get_label() for ln in lines] == ["mode=conventional", "mode=full-cycle"]
        for ln, mode in zip(lines, ("conventional", "full-cycle"), strict=True):
            np.testing.assert_allclose(ln.get_xdata(), [40, 50, 60])
            np.testing.assert_allclose(ln.get_ydata(), [
                factor * expected[(case, mode)][t] for t in (40, 50, 60)])
        assert len(ax.collections) == 2  # the 25-75 % bands
        assert ax.get_xlabel() == "align.stages.0.t_z_s (s)"
    assert fig.axes[0].get_ylabel() == f"median |error_t3_deg yaw| ({unit})"
    assert fig.axes[0].get_ylim() == fig.axes[1].get_ylim()  # one scale per row
    vec = figs["batch_error_t3_deg_vs_t_z_s"]
    assert len(vec.axes) == 6  # pitch, roll, yaw rows × two cases
    assert [ax.get_ylabel().rsplit(" (", 1)[0] for ax in vec.axes[::2]] == [
        f"median |error_t3_deg {c}|" for c in ("pitch", "roll", "yaw")]
    assert vec.axes[4].get_ylabel() == fig.axes[0].get_ylabel()
    np.testing.assert_allclose(data_series(vec.axes[4])[0].get_ydata(),
                               data_series(fig.axes[0])[0].get_ydata())


def test_sweep_figure_cases_are_lines_when_nothing_else_is():
    """Cases and one numeric key: the cases draw the lines of one panel; a row's y axis is
    logarithmic when its medians span more than a factor 30."""
    from gcalign.app.batch.plots import numeric_axes, sweep_figure

    overrides = [{"case": c, "x": x} for c in ("a", "b") for x in (1, 2)]
    values = np.array([[1e-3], [2e-3], [0.5], [1.0]]).repeat(3, axis=0)
    variant = np.arange(4).repeat(3)
    assert numeric_axes({"case": ["a", "b"], "x": [1, 2], "m": ["u", "v"], "y": [3]}) == ["x"]
    fig = sweep_figure("err_deg", values, variant, overrides, "x", units="deg")
    assert len(fig.axes) == 1
    ax = fig.axes[0]
    assert [ln.get_label() for ln in data_series(ax)] == ["case=a", "case=b"]
    assert ax.get_yscale() == "log"
    np.testing.assert_allclose(data_series(ax)[1].get_ydata(), [0.5, 1.0])


@pytest.mark.slow
def test_plot_command_writes_pngs_next_to_the_file(align_files, batch_file, tmp_path):
    for path, n in ((align_files["full-cycle"], 2), (batch_file, 2)):
        res = runner.invoke(app, ["plot", str(path), "--json"])
        assert res.exit_code == 0, res.output
        written = json.loads(res.stdout)["figures"]
        assert len(written) == n
        for p in map(Path, written):
            assert p.parent == path.with_name(path.stem + "_plots")
            data = p.read_bytes()
            assert data.startswith(PNG) and len(data) > 10_000
    out_dir = tmp_path / "figs"
    res = runner.invoke(app, ["plot", str(batch_file), "-o", str(out_dir)])
    assert res.exit_code == 0, res.output
    assert sorted(p.name for p in out_dir.iterdir()) == ["batch_equivalent_s.png",
                                                          "batch_error_t3_deg.png"]
    assert str(out_dir / "batch_error_t3_deg.png") in res.stdout


def test_plot_bad_input(tmp_path):
    res = runner.invoke(app, ["plot", str(tmp_path / "missing.h5")])
    assert res.exit_code == 2 and "file not found" in res.stderr
    bad = tmp_path / "x.h5"
    bad.write_text("not hdf5")
    res = runner.invoke(app, ["plot", str(bad)])
    assert res.exit_code == 2 and "not an HDF5 file" in res.stderr


# ------------------------------------------------------------ navigate, truth, IMU output


def run_each(commands, scenario: Path, folder: Path) -> dict[str, Path]:
    """Run each command on `scenario`; its results file by command name."""
    out = {}
    for cmd in commands:
        out[cmd] = folder / f"{cmd}.h5"
        res = runner.invoke(app, [cmd, str(scenario), "-o", str(out[cmd])])
        assert res.exit_code == 0, res.output
    return out


@pytest.fixture(scope="module")
def sim_and_nav(tmp_path_factory):
    """simulate and navigate of the small moving scenario (80 s, navigation-grade IMU)."""
    folder = tmp_path_factory.mktemp("nav")
    sc = folder / "m.yaml"
    d = {k: v for k, v in copy.deepcopy(SMALL).items() if k != "align"}
    sc.write_text(yaml.safe_dump(d))
    return run_each(("simulate", "navigate"), sc, folder)


def test_navigate_error_figure_phi_velocity_position_and_horizontal_norm(sim_and_nav):
    figs = readback.figures_for(sim_and_nav["navigate"])
    assert set(figs) == {"navigate_error"}
    fig = figs["navigate_error"]
    phi_ax, v_ax, p_ax = fig.axes
    with results.open_results(sim_and_nav["navigate"]) as f:
        t, phi = f["navigate/t"][()], f["navigate/error/phi"][()]
        pos = f["navigate/error/pos"][()]
    scale, unit = plots.angle_scale(phi)
    assert phi_ax.get_ylabel() == f"misalignment ({unit})"
    assert [ln.get_label() for ln in data_series(phi_ax)] == ["φ east", "φ north", "φ up"]
    x, mean, _, _ = plots.envelope(t - t[0], phi[:, 2] * scale)  # 8001 rows: bins
    np.testing.assert_allclose(data_series(phi_ax)[2].get_ydata(), mean)
    np.testing.assert_allclose(data_series(phi_ax)[0].get_xdata(), x)
    assert [ln.get_label() for ln in data_series(v_ax)] == ["east", "north", "up"]
    horiz = data_series(p_ax)[-1]
    assert horiz.get_label() == "horizontal |·|"
    np.testing.assert_allclose(horiz.get_ydata(),
                               plots.envelope(t, np.hypot(pos[:, 0], pos[:, 1]))[1])
    assert p_ax.get_xlabel() == "time from the start (s)"
    for ax in fig.axes:  # legends beside the panels, never on the data
        legend = ax.get_legend()
        assert legend is not None and legend.get_bbox_to_anchor().x0 > ax.bbox.x1 - 1


def test_envelope_bins_are_means_minima_and_maxima():
    x = np.arange(10.0)
    y = np.array([0, 5, 1, 2, -3, 4, 9, 0, 1, 1.0])
    xc, mean, lo, hi = plots.envelope(x, y, max_points=4)  # bins of 3, the last row dropped
    np.testing.assert_allclose(xc, [1, 4, 7])
    np.testing.assert_allclose(mean, [2, 1, 10 / 3])
    np.testing.assert_allclose(lo, [0, -3, 0])
    np.testing.assert_allclose(hi, [5, 4, 9])
    assert plots.envelope(x, y, max_points=10)[1] is not None  # short: as it is
    np.testing.assert_array_equal(plots.envelope(x, y, max_points=10)[1], y)


def test_simulate_figures_truth_and_imu_output(sim_and_nav):
    figs = readback.figures_for(sim_and_nav["simulate"])
    assert set(figs) == {"truth", "imu"}
    truth = figs["truth"]
    assert [ln.get_label() for ln in data_series(truth.axes[0])] == ["pitch", "roll", "yaw"]
    assert truth.axes[1].get_ylabel().startswith("velocity (m/s)")
    imu = figs["imu"]
    assert len(imu.axes) == 6  # gyro x, y, z over accel x, y, z
    with results.open_results(sim_and_nav["simulate"]) as f:
        dtheta, dv, ts = f["imu/dtheta"][()], f["imu/dv"][()], float(f["imu"].attrs["ts"])
    w = dtheta / ts
    scale, unit = plots.rate_scale(w)
    assert unit == "deg/s"  # the base turns at 1°/s
    assert imu.axes[0].get_ylabel() == "angular rate (deg/s)"
    assert imu.axes[3].get_ylabel() == "specific force (m/s²)"
    assert len(w) == 8000 > plots.MAX_POINTS  # drawn as bins: means, and a min-max band
    k = int(np.ceil(len(w) / plots.MAX_POINTS))
    n = len(w) // k * k
    gyro_z = data_series(imu.axes[2])[0]
    np.testing.assert_allclose(gyro_z.get_ydata(), (w[:n, 2] * scale).reshape(-1, k).mean(1))
    band = imu.axes[2].collections[0].get_paths()[0].vertices[:, 1]
    assert band.max() == pytest.approx(w[:n, 2].max() * scale)  # a peak is not averaged away
    accel_y = data_series(imu.axes[4])[0]
    np.testing.assert_allclose(accel_y.get_ydata(), (dv[:n, 1] / ts).reshape(-1, k).mean(1))


@pytest.mark.slow
def test_plot_of_a_recorded_data_file_draws_its_imu_output(tmp_path):
    """`gcalign plot` of the compressed recording itself: its IMU output (°/s, the vehicle
    is disturbed), the file's own axes and rate."""
    res = runner.invoke(app, ["plot", str(ROOT / "tests/data/lasergyro.imu.xz"), "-o",
                              str(tmp_path), "--json"])
    assert res.exit_code == 0, res.output
    out = json.loads(res.stdout)
    assert out["kind"] == "data" and [Path(p).name for p in out["figures"]] == ["imu.png"]
    assert Path(out["figures"][0]).read_bytes().startswith(PNG)
    fig = readback.figures_for(ROOT / "tests/data/lasergyro.imu.xz")["imu"]
    assert "increments / 10 ms" in fig.get_suptitle()
    assert fig.axes[3].get_xlabel() == "time from the start (min)"  # 1847 s
    # the specific force along z is gravity: its bin means sit at 9.79 m/s²
    mean_z = data_series(fig.axes[5])[0].get_ydata()
    assert np.median(mean_z) == pytest.approx(9.79, abs=0.02)


def test_a_results_file_without_figures_says_so(tmp_path):
    path = tmp_path / "empty.h5"
    with results.atomic_h5(path) as f:
        results.write_header(f, "align", "", 1, {"scenario": "x"})
    res = runner.invoke(app, ["plot", str(path)])
    assert res.exit_code == 2
    assert "a 'align' results file needs its /align group; it has none" in res.output


# ------------------------------------------------------------ navigate on recorded data


@pytest.mark.slow
def test_navigate_figure_of_recorded_data_is_the_solution_and_its_drift(tmp_path):
    """No truth: pitch/roll, yaw (unwrapped), velocity and the displacement from the start
    (east, north, horizontal norm) read back from the file; minutes for a 30 min run."""
    from gcalign.app.navigate.run import position_error_enu

    nav = tmp_path / "nav.h5"
    res = runner.invoke(app, ["navigate", str(ROOT / "tests/data/lasergyro.imu.xz"),
                              "--init", "header", "--duration", "1800", "-o", str(nav)])
    assert res.exit_code == 0, res.output
    figs = readback.figures_for(nav)
    assert set(figs) == {"navigate"}
    fig = figs["navigate"]
    assert "no truth" in fig.get_suptitle() and "estimate vs truth" not in fig.get_suptitle()
    att_ax, yaw_ax, v_ax, d_ax = fig.axes
    with results.open_results(nav) as f:
        t, att = f["navigate/t"][()], f["navigate/att"][()]
        v_n, pos = f["navigate/v_n"][()], f["navigate/pos"][()]
    assert [ln.get_label() for ln in data_series(att_ax)] == ["pitch", "roll"]
    assert att_ax.get_ylabel() == "pitch, roll (deg)" and yaw_ax.get_ylabel() == "yaw (deg)"
    x, mean, _, _ = plots.envelope(t - t[0], np.degrees(att[:, 1]))
    np.testing.assert_allclose(data_series(att_ax)[1].get_ydata(), mean)
    np.testing.assert_allclose(data_series(yaw_ax)[0].get_ydata(),
                               plots.envelope(t, np.degrees(np.unwrap(att[:, 2])))[1])
    assert [ln.get_label() for ln in data_series(v_ax)] == ["east", "north", "up"]
    np.testing.assert_allclose(data_series(v_ax)[0].get_ydata(),
                               plots.envelope(t, v_n[:, 0])[1])
    disp = position_error_enu(pos, np.broadcast_to(pos[0], pos.shape))
    assert [ln.get_label() for ln in data_series(d_ax)] == ["east", "north", "horizontal |·|"]
    np.testing.assert_allclose(data_series(d_ax)[2].get_ydata(),
                               plots.envelope(t, np.hypot(disp[:, 0], disp[:, 1]))[1])
    assert d_ax.get_xlabel() == "time from the start (min)"
    np.testing.assert_allclose(data_series(d_ax)[0].get_xdata(), x / 60.0)
    for ax in fig.axes:
        legend = ax.get_legend()
        assert legend is not None and legend.get_bbox_to_anchor().x0 > ax.bbox.x1 - 1


# ------------------------------------------------------------ calibrate, observability


@pytest.fixture(scope="module")
def calibrate_file(tmp_path_factory):
    """`gcalign calibrate` and `gcalign observability` on a short flight (the seed-002
    test flight of tests/calibrate_cases.py, 25 Hz)."""
    from calibrate_cases import SHORT

    folder = tmp_path_factory.mktemp("cal")
    sc = folder / "short.yaml"
    sc.write_text(yaml.safe_dump({**copy.deepcopy(SHORT), "imu": {
        "rate_hz": 25, "seed": 2, "gyro": {"bias_dph": [0.01, -0.01, 0.01]},
        "accel": {"bias_ug": [50, -50, 50]}}}))
    return run_each(("calibrate", "observability"), sc, folder)


@pytest.mark.slow
def test_calibrate_figures_estimates_sigma_errors_innovations(calibrate_file):
    """Each panel draws the file's series in the display unit of its state (°/h, µg, ppm,
    ″/′, m/s): the estimate, its ±3σ band and the injected truth; σ/σ0 from 1 at the start;
    the navigation error estimate − truth; standardized innovations and NIS; one legend
    outside the panels."""
    from gcalign.app.calibrate.plots import read_runs

    path = calibrate_file["calibrate"]
    figs = readback.figures_for(path)
    assert set(figs) == {"trajectory", "sensor_biases", "scale_factors", "sigma",
                         "navigation_errors", "innovations", "solution_errors"}
    with results.open_results(path) as f:
        runs, attrs = read_runs(f)
    run = runs[0].result
    names = attrs["states"].split(",")
    units = attrs["display_units"].split(",")
    scale = np.asarray(attrs["display_scale"])
    t = run.t
    for fig_name, states in (("sensor_biases", ["ebx", "eby", "ebz", "dbx", "dby", "dbz"]),
                             ("scale_factors", ["dKgx", "dKgy", "dKgz", "dKax", "dKay",
                                                "dKaz"])):
        fig = figs[fig_name]
        for ax, name in zip(fig.axes, states, strict=True):
            i = names.index(name)
            assert ax.get_title() == name
            est = data_series(ax)[0]
            assert est.get_label() == "estimate"
            np.testing.assert_allclose(est.get_ydata(), run.estimate[:, i] * scale[i])
            np.testing.assert_allclose(est.get_xdata(), t)
            truth = [ln for ln in ax.lines if ln.get_label() == "truth"][0]
            assert truth.get_ydata()[0] == pytest.approx(run.truth[0, i] * scale[i])
            band = ax.collections[0].get_paths()[0].vertices[:, 1]
            top = run.estimate[:, i] * scale[i] + 3 * run.sigma[:, i] * scale[i]
            assert band.max() == pytest.approx(top.max())
            lo, hi = ax.get_ylim()
            assert lo == pytest.approx(-hi)  # symmetric about zero: the sign reads at once
            assert abs(truth.get_ydata()[0]) < hi  # the truth is inside the panel
            assert ax.get_ylabel() == {"deg/h": "°/h", "ug": "µg", "ppm": "ppm"}[units[i]]
        assert fig.legends and all(ax.get_legend() is None for ax in fig.axes)
    assert [units[names.index(n)] for n in ("ebx", "dbx", "dKgx")] == ["deg/h", "ug", "ppm"]
    sig = figs["sigma"]
    # a group whose σ stays within 1 % of its P0 everywhere draws what it learnt, 1 − σ/σ0
    # (σ/σ0 would read 1.00 on every tick); on this 162 s flight the gyro biases are one
    groups = ("gyro bias ε", "accelerometer bias ∇", "gyro scale factor δKg",
              "accelerometer scale factor δKa")
    stems = ("eb", "db", "dKg", "dKa")
    held = [min(float(np.min(run.sigma[:, names.index(st + a)]
                             / run.sigma[0, names.index(st + a)])) for a in "xyz") > 0.99
            for st in stems]
    assert [ax.get_title() for ax in sig.axes] == [
        g + (" — σ within 1 % of P0" if h else "") for g, h in zip(groups, held, strict=True)]
    ln = data_series(sig.axes[0])[2]  # gyro bias z
    assert ln.get_label() == "z" and sig.axes[0].get_yscale() == "log"
    i = names.index("ebz")
    ratio = run.sigma[:, i] / run.sigma[0, i]
    want = np.maximum(1.0 - ratio, 1e-16) if held[0] else ratio
    np.testing.assert_allclose(ln.get_ydata(), want)
    nav = figs["navigation_errors"]
    assert [ax.get_title() for ax in nav.axes] == names[:6]
    for ax, i in zip(nav.axes, range(6), strict=True):
        err = data_series(ax)[0]
        assert err.get_label() == "error"
        np.testing.assert_allclose(err.get_ydata(),
                                   (run.estimate[:, i] - run.truth[:, i]) * scale[i])
        assert ax.get_ylabel() in ("arcsec", "arcmin", "m/s")
    inn = figs["innovations"]
    z = data_series(inn.axes[0])
    assert [ln.get_label() for ln in z] == list(run.measure_names)
    np.testing.assert_allclose(z[0].get_ydata(), run.standardized[:, 0])
    np.testing.assert_allclose(data_series(inn.axes[1])[0].get_ydata(),
                               np.maximum(run.nis, 1e-6))
    assert inn.axes[1].get_yscale() == "log"
    traj = figs["trajectory"]
    track, height = traj.axes[:2]
    assert track.get_xlabel() == "east (km)" and height.get_ylabel().startswith("height")


def test_observability_heat_maps_are_log10_of_the_file(calibrate_file):
    """The cells are log10 η (zeros masked, drawn grey) of /observability, segments ×
    states, the text in each cell its rounded exponent."""
    path = calibrate_file["observability"]
    figs = readback.figures_for(path)
    assert {"trajectory", "observability_segments", "observability_cumulative"} <= set(figs)
    with results.open_results(path) as f:
        g = f["observability"]
        eta, eta_cum = g["eta"][()], g["eta_cum"][()]
        states = g.attrs["states"]
        states = (states.decode() if isinstance(states, bytes) else states).split(",")
    for key, values in (("observability_segments", eta), ("observability_cumulative", eta_cum)):
        ax = figs[key].axes[0]
        img = ax.images[0].get_array()
        assert img.shape == values.shape == (values.shape[0], 21)
        pos = values > 0
        np.testing.assert_allclose(img[pos], np.log10(values[pos]))
        assert np.all(np.ma.getmaskarray(img)[~pos])  # unobservable: masked (grey)
        assert [tk.get_text() for tk in ax.get_xticklabels()] == states
        texts = [tx.get_text() for tx in ax.texts]
        assert len(texts) == values.size
        assert texts[1] == (f"{round(np.log10(values[0, 1]))}" if values[0, 1] > 0 else "·")
