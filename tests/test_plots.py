"""`gcalign plot` and gcalign.app.plots: which figures, which axes, how many series, PNG files."""

from __future__ import annotations

import copy
import json
from pathlib import Path

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from gcalign.app import plots
from gcalign.cli import app
from gcalign.io import results

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
    "align": {"mode": "full-cycle", "t1_s": 10, "t2_s": 60, "t3_s": 70, "passes": 3,
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
    figs = plots.figures_for(align_files["full-cycle"])
    assert set(figs) == {"align_error", "align_attitude"}
    err = figs["align_error"]
    assert len(err.axes) == 3
    for ax, name in zip(err.axes, ("pitch", "roll", "yaw"), strict=True):
        assert len(data_series(ax)) == 3  # one line per pass
        assert len(boundaries(ax)) == 2  # between passes 1|2 and 2|3
        assert ax.get_ylabel().startswith(f"{name} error (deg)")
    assert "equivalent time (s)" in err.axes[-1].get_xlabel()
    # Passes laid end to end: 10 s + 3 × 50 s of fine-alignment data.
    lines = data_series(err.axes[2])
    np.testing.assert_allclose([ln.get_xdata()[0] for ln in lines], [10, 60, 110])
    np.testing.assert_allclose(lines[-1].get_xdata()[-1], 160)
    np.testing.assert_allclose([b.get_xdata()[0] for b in boundaries(err.axes[0])], [60, 110])
    # The reverse pass's error, read from the file, is what is drawn (deg).
    with results.open_results(align_files["full-cycle"]) as f:
        e1 = f["align/pass_01/error"][()]
    np.testing.assert_allclose(lines[1].get_ydata(), np.degrees(e1[:, 2]))
    att = figs["align_attitude"]
    assert len(att.axes) == 3
    for ax in att.axes:
        labels = [ln.get_label() for ln in data_series(ax)]
        assert len(labels) == 4 and labels[-1] == "truth"
        assert ax.get_ylabel().endswith("(deg)")
    assert att.get_suptitle() and err.get_suptitle()


def test_conventional_has_one_pass_and_no_boundary(align_files):
    fig = plots.figures_for(align_files["conventional"])["align_error"]
    for ax in fig.axes:
        assert len(data_series(ax)) == 1 and not boundaries(ax)


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
    figs = plots.figures_for(path)
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
    assert len(diff.axes) == 1 and len(data_series(diff.axes[0])) == 1
    assert diff.axes[0].get_ylabel() == "difference (arcsec)"


def test_northfind_figures_from_the_real_command(tmp_path):
    out = tmp_path / "nf.h5"
    res = runner.invoke(app, ["northfind", "-o", str(out)])
    assert res.exit_code == 0, res.output
    fig = plots.figures_for(out)["northfind_error"]
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


def test_batch_figures_box_per_variant_and_component(batch_file):
    figs = plots.figures_for(batch_file)
    assert set(figs) == {"batch_error_t3_deg", "batch_equivalent_s"}
    fig = figs["batch_error_t3_deg"]
    assert len(fig.axes) == 3  # pitch, roll, yaw
    for ax, comp in zip(fig.axes, ("pitch", "roll", "yaw"), strict=True):
        assert len(ax.patches) == 4  # one box per variant
        assert comp in ax.get_ylabel() and "(deg)" in ax.get_ylabel()
    labels = [t.get_text() for t in fig.axes[-1].get_xticklabels()]  # shared x: bottom axes
    assert labels == ["mode=conventional\ncompensation=none",
                      "mode=conventional\ncompensation=continued",
                      "mode=full-cycle\ncompensation=none",
                      "mode=full-cycle\ncompensation=continued"]
    scalar = figs["batch_equivalent_s"]
    assert len(scalar.axes) == 1 and len(scalar.axes[0].patches) == 4
    assert scalar.axes[0].get_ylabel() == "equivalent_s (s)"


def test_sweep_figure_median_against_the_numeric_key(sweep_file):
    """A numeric grid key gives lines instead of boxes: x = its values (sorted), y = the
    median over seeds of |metric| of each variant, read back from /batch/runs; one line
    per other grid value (mode), one column per case, one row per component."""
    figs = plots.figures_for(sweep_file)
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
    fig = figs["batch_error_t3_deg_2_vs_t_z_s"]
    assert len(fig.axes) == 2  # one row (a scalar metric) × two cases
    for ax, case in zip(fig.axes, ("noisy", "quiet"), strict=True):
        assert ax.get_title() == f"case: {case}"
        lines = data_series(ax)
        assert [ln.get_label() for ln in lines] == ["mode=conventional", "mode=full-cycle"]
        for ln, mode in zip(lines, ("conventional", "full-cycle"), strict=True):
            np.testing.assert_allclose(ln.get_xdata(), [40, 50, 60])
            np.testing.assert_allclose(ln.get_ydata(),
                                       [expected[(case, mode)][t] for t in (40, 50, 60)])
        assert len(ax.collections) == 2  # the 25-75 % bands
        assert ax.get_xlabel() == "align.stages.0.t_z_s (s)"
    assert fig.axes[0].get_ylabel() == "median |error_t3_deg yaw| (deg)"
    assert fig.axes[0].get_ylim() == fig.axes[1].get_ylim()  # one scale per row
    vec = figs["batch_error_t3_deg_vs_t_z_s"]
    assert len(vec.axes) == 6  # pitch, roll, yaw rows × two cases
    assert [ax.get_ylabel() for ax in vec.axes[::2]] == [
        f"median |error_t3_deg {c}| (deg)" for c in ("pitch", "roll", "yaw")]
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
