"""The Python module (issue 12): the same numbers as the command line, the same errors, and
batches that give the same rows locally and on a Dask cluster."""

import csv
import math
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import pytest

import kin2grf

CLI = os.environ.get("KIN2GRF_CLI", "kin2grf")
DATA = Path(os.environ.get("KIN2GRF_DATA_DIR", Path(__file__).resolve().parents[2] / ".." / "shared" / "data"))


@pytest.fixture(scope="module")
def example(tmp_path_factory):
    d = tmp_path_factory.mktemp("example")
    subprocess.run([CLI, "make-example", "--out-dir", str(d)], check=True, capture_output=True)
    return d


def cli_csv(trial, *args, tmp):
    out = Path(tmp) / "cli.csv"
    subprocess.run([CLI, "estimate", str(trial), *args, "--csv", str(out)], check=True, capture_output=True)
    with open(out, newline="") as f:
        return list(csv.reader(f))


def formatted(column, x):
    """A value as the CLI's CSV writes it: counts as integers, the rest %.6g, NaN empty."""
    if column == "frame" or column.startswith("contact_") or column == "iterations":
        return str(int(x))
    return "" if not math.isfinite(x) else "%.6g" % x


def assert_same_as_cli(r, rows):
    assert r.columns == rows[0]
    assert r.values.shape == (len(rows) - 1, len(rows[0]))
    for i, row in enumerate(rows[1:]):
        for k, cell in enumerate(row):
            assert formatted(r.columns[k], r.values[i, k]) == cell, (i, r.columns[k])
    # And numerically: the CSV is the module's values to 6 significant digits.
    csv_values = np.array([[float(c) if c else np.nan for c in row] for row in rows[1:]])
    np.testing.assert_allclose(r.values, csv_values, rtol=1e-5, atol=1e-9, equal_nan=True)


def test_estimate_equals_the_cli_csv_on_the_example(example, tmp_path):
    trial = example / "example_walk.c3d"
    assert_same_as_cli(kin2grf.estimate(trial), cli_csv(trial, tmp=tmp_path))
    # Settings by keyword, the same as the flags.
    r = kin2grf.estimate(trial, paper=True, r=2000.0, grm_reference=(1.0, 0.0), post_cutoff=10)
    assert_same_as_cli(r, cli_csv(trial, "--paper", "--r", "2000", "--grm-reference", "1", "0", "--post-cutoff", "10", tmp=tmp_path))
    assert r.summary["settings"]["r_N_per_m"] == 2000.0
    assert r.summary["settings"]["paper_configuration"] is True


def test_estimate_equals_the_cli_csv_on_a_shared_trial(tmp_path):
    trial = DATA / "opensim_c3d_overground_walk" / "walking2.c3d"
    if not trial.exists():
        pytest.skip(f"shared recordings not found at {DATA} (set KIN2GRF_DATA_DIR)")
    assert_same_as_cli(kin2grf.estimate(trial, mass=64.9), cli_csv(trial, "--mass", "64.9", tmp=tmp_path))


def test_estimate_writes_the_opensim_set(example, tmp_path):
    r = kin2grf.estimate(example / "example_walk.c3d", opensim=tmp_path / "set")
    for f in ("example_walk_grf.mot", "example_walk_markers.trc", "example_walk_external_loads.xml"):
        assert (tmp_path / "set" / f).exists(), f
    assert "kin2grf_frame=OpenSim ground" in (tmp_path / "set" / "example_walk_grf.mot").read_text()
    assert r.summary["mass_kg"] == 70.0
    # The result writes the same files, and the -o .mot is the set's .mot.
    written = r.write_opensim(tmp_path / "again")
    assert [Path(p).name for p in written] == ["example_walk_grf.mot", "example_walk_markers.trc", "example_walk_external_loads.xml"]
    mot = r.write_mot(tmp_path / "o.mot")
    assert Path(mot).read_text() == (tmp_path / "set" / "example_walk_grf.mot").read_text()
    assert "kin2grf_frame=lab" in Path(r.write_mot(tmp_path / "lab.mot", lab_frame=True)).read_text()
    # and the C3D with the estimated platforms, byte for byte what `kin2grf estimate --c3d` writes.
    c3d = r.write_c3d(tmp_path / "estimated.c3d")
    cli = tmp_path / "cli.c3d"
    subprocess.run([CLI, "estimate", str(example / "example_walk.c3d"), "--c3d", str(cli)], check=True, capture_output=True)
    assert Path(c3d).read_bytes() == cli.read_bytes()


def test_table_and_columns(example):
    r = kin2grf.estimate(example / "example_walk.c3d")
    assert r["grf_vertical_r_N"].shape == (r.values.shape[0],)
    t = r.table
    try:
        import pandas  # noqa: F401
        assert list(t.columns) == r.columns
    except ImportError:
        assert set(t) == set(r.columns)
    # Frame numbers and contact states are integers, as in the CSV.
    for c in ("frame", "contact_r", "contact_l", "iterations"):
        assert np.issubdtype(np.asarray(t[c]).dtype, np.integer), c
    assert r.summary["mass_kg"] == 70.0


def _cli_csv_rows(tmp_path, command, trial, option):
    """The rows of a CSV the CLI writes: `kin2grf COMMAND TRIAL OPTION FILE`."""
    out = tmp_path / "cli.csv"
    subprocess.run([CLI, command, str(trial), option, str(out)], check=True, capture_output=True)
    with open(out, newline="") as f:
        return list(csv.DictReader(f))


def _records(table):
    """A DataFrame's rows as dicts, or those of a dict of arrays / a list of dicts (without pandas)."""
    if hasattr(table, "to_dict"):
        return table.to_dict("records")
    if isinstance(table, dict):
        return [dict(zip(table, v)) for v in zip(*table.values())]
    return table


def _same_numbers(mine, theirs, keys):
    for k in keys:
        assert abs(float(theirs[k]) - mine[k]) <= 1e-5 * abs(mine[k]) + 1e-9, k


def test_stances_are_the_cli_stances_csv(example, tmp_path):
    """Estimate.stances: the summary's stance parameters as ``--stances`` writes them, row for row."""
    trial = example / "example_walk.c3d"
    rows = _cli_csv_rows(tmp_path, "estimate", trial, "--stances")
    records = _records(kin2grf.estimate(trial).stances)
    assert len(records) == len(rows) >= 4
    for mine, theirs in zip(records, rows):
        assert mine["side"] == theirs["side"]
        assert int(theirs["complete"]) == int(mine["complete"])
        _same_numbers(mine, theirs, ("start_s", "duration_s", "vertical_first_peak_N", "braking_impulse_Ns"))


def test_stance_curves_are_the_cli_stance_curves_csv(example, tmp_path):
    """Estimate.stance_curves: every complete stance at 0..100 % as ``--stance-curves`` writes it."""
    trial = example / "example_walk.c3d"
    rows = _cli_csv_rows(tmp_path, "estimate", trial, "--stance-curves")
    records = _records(kin2grf.estimate(trial).stance_curves)
    assert len(records) == len(rows) >= 2 * 101
    assert [float(x["percent"]) for x in rows[:101]] == list(range(101))
    for mine, theirs in zip(records, rows):
        assert mine["side"] == theirs["side"]
        assert int(mine["frame_first"]) == int(theirs["frame_first"])
        _same_numbers(mine, theirs, ("percent", "grf_vertical_bw", "cop_progression_m", "torque_knee_Nm_per_kg"))


def test_validate_gives_the_cli_stance_curves(example, tmp_path):
    """validate()["stance_curves"]: every scored plate stance at 0..100 %, as ``validate --stance-curves``."""
    trial = example / "example_walk.c3d"
    rows = _cli_csv_rows(tmp_path, "validate", trial, "--stance-curves")
    v = kin2grf.validate(trial)
    records = _records(v["stance_curves"])
    assert len(records) == len(rows) == 101 * len(v["per_foot"]) > 0
    for mine, theirs in zip(records, rows):
        assert (mine["side"], mine["plate"]) == (theirs["side"], theirs["plate"])
        _same_numbers(mine, theirs, ("percent", "vertical_bw_estimate", "vertical_bw_plate"))


def test_mediolateral_adds_the_lateral_columns(example):
    r0 = kin2grf.estimate(example / "example_walk.c3d")
    r1 = kin2grf.estimate(example / "example_walk.c3d", mediolateral=True)
    assert r1.columns == r0.columns + ["grf_lateral_r_N", "grf_lateral_l_N", "cop_lateral_r_m", "cop_lateral_l_m"]
    assert np.array_equal(r1["grf_vertical_r_N"], r0["grf_vertical_r_N"])
    # The lateral COP where, and only where, the COP along the foot exists.
    for s in "rl":
        assert np.array_equal(np.isnan(r1[f"cop_lateral_{s}_m"]), np.isnan(r1[f"cop_x_{s}_m"]))
        assert np.isfinite(r1[f"cop_lateral_{s}_m"]).sum() > 0
    assert r1.summary["settings"]["mediolateral"] is True


def test_help_lists_every_setting():
    for f in (kin2grf.estimate, kin2grf.validate):
        for name in ("speed_gate_ratio", "mass", "touchdown_fraction", "post_cutoff_floor", "paper", "mediolateral"):
            assert f"    {name}" in f.__doc__, (f.__name__, name)


def test_frames_cut_the_trial_as_the_cli_does(example, tmp_path):
    trial = example / "example_walk.c3d"
    r = kin2grf.estimate(trial, frames="51:250")
    assert_same_as_cli(r, cli_csv(trial, "--frames", "51:250", tmp=tmp_path))
    assert r.summary["settings"]["frames"] == "51:250"
    assert r.summary["frames"]["first"] >= 51 and r.summary["frames"]["last"] <= 250
    with pytest.raises(kin2grf.InputError, match="not within the recording's frames"):
        kin2grf.estimate(trial, frames="0:250")


def test_validate_compares_the_example_plates(example):
    v = kin2grf.validate(example / "example_walk.c3d")
    assert v["mean_rrmse_percent"]["all"]["stances"] == 2
    assert v["sync"]["applied_shift_ms"] == 0.0
    shifted = kin2grf.validate(example / "example_walk.c3d", sync=0.02)
    assert shifted["sync"]["applied_shift_ms"] == pytest.approx(20.0)
    with pytest.raises(kin2grf.InputError, match="--sync"):
        kin2grf.validate(example / "example_walk.c3d", sync="sometimes")
    # How onsets are timed: by default, each stance says which reference timed it; "ramp" times all
    # by the ramps, with the crossings' figures kept beside.
    for s in v["per_foot"]:
        assert s["timing_ms"]["onset_timed_by"] in ("crossing", "ramp")
        assert s["timing_ms"]["offset_timed_by"] == "crossing"
    ramped = kin2grf.validate(example / "example_walk.c3d", timing="ramp")
    assert ramped["settings"]["timing"] == "ramp"
    for s in ramped["per_foot"]:
        assert s["timing_ms"]["onset_timed_by"] == "ramp" and s["timing_ms"]["offset_timed_by"] == "ramp"
        assert s["timing_ms"]["onset"] == s["timing_ms"]["onset_ramp"]
    with pytest.raises(kin2grf.InputError, match="--timing"):
        kin2grf.validate(example / "example_walk.c3d", timing="sometimes")
    assert isinstance(v["estimate"], kin2grf.Estimate)
    with pytest.raises(kin2grf.InputError, match="no force plates"):
        kin2grf.validate(example / "example_walk.trc", mass=70)


def test_errors_carry_the_cli_messages(example, tmp_path):
    with pytest.raises(kin2grf.InputError, match="no-such.c3d"):
        kin2grf.estimate(tmp_path / "no-such.c3d")
    with pytest.raises(ValueError, match="activation parameter r"):
        kin2grf.estimate(example / "example_walk.c3d", r=-1)
    with pytest.raises(kin2grf.InputError, match="foot-model"):
        kin2grf.estimate(example / "example_walk.c3d", foot_model="no-such-model")
    with pytest.raises(TypeError, match="no_such_setting"):
        kin2grf.estimate(example / "example_walk.c3d", no_such_setting=1)
    names = {s["name"] for s in kin2grf.settings()}
    assert {"static", "markers", "mass", "r", "speed_gate_ratio", "paper", "grm_reference"} <= names


def batch_lines(example, tmp):
    return [
        f"walking|own|walk|{example / 'example_walk.c3d'}",
        f"walking|own|missing|{Path(tmp) / 'no-such.trc'} --mass 70",
        f"squat|own|squat|{example / 'example_squat.trc'} --mass 70",
    ]


def without_timing(rows):
    """Rows without the wall time, NaN as None (NaN is not equal to itself)."""
    def plain(v):
        return None if isinstance(v, float) and math.isnan(v) else v
    return [{k: plain(v) for k, v in r.items() if k != "seconds"} for r in rows]


def test_batch_locally_and_on_a_dask_cluster(example, tmp_path):
    pd = pytest.importorskip("pandas")
    lines = batch_lines(example, tmp_path)
    local = kin2grf.batch(lines, jobs=2)
    assert list(local["name"]) == ["walk", "missing", "squat"]
    assert list(local["ok"]) == [True, False, True]
    assert "no-such.trc" in local["error"][1]
    assert local["stances"][0] == 2
    # The CSV's column order and names (kin2grf batch --csv), then the row's other fields.
    assert list(local.columns)[:5] == ["activity", "lab", "name", "trial", "ok"]
    assert list(local.columns).index("vertical_rrmse_percent") < list(local.columns).index("error")
    assert "validated" in local.columns
    # The file form of the list gives the same rows.
    listing = tmp_path / "list.txt"
    listing.write_text("# a comment\n" + "\n".join(lines) + "\n")
    one = kin2grf.batch(listing, jobs=1)
    assert without_timing(one.to_dict("records")) == without_timing(local.to_dict("records"))

    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                                  silence_logs=40) as cluster, distributed.Client(cluster) as client:
        remote = kin2grf.batch(lines, client=client)
    assert isinstance(remote, pd.DataFrame)
    assert without_timing(remote.to_dict("records")) == without_timing(local.to_dict("records"))


def test_the_readme_example_runs_as_written(tmp_path):
    """The README's first Python example, verbatim, from a copy of the repository's root layout
    (its bundled walk) so that its output folder lands in tmp_path."""
    root = Path(__file__).resolve().parents[2]
    text = (root / "README.md").read_text()
    start = text.index("```python\n") + len("```python\n")
    code = text[start:text.index("```", start)]
    (tmp_path / "data").mkdir()
    os.symlink(root / "data" / "example", tmp_path / "data" / "example")
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(p for p in sys.path if p))
    done = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, env=env, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr[-2000:]
    assert "grf_vertical_r_N" in done.stdout
    assert "cop_lateral_r_m" in done.stdout and "hip_frontal_Nm_per_kg" in done.stdout  # the 3D lines
    assert (tmp_path / "out" / "python-opensim" / "walking2_grf.mot").exists()
    assert (tmp_path / "out" / "python-grf.mot").read_text() == (tmp_path / "out" / "python-opensim" / "walking2_grf.mot").read_text()


def test_info_describes_a_file_and_names_its_marker_set(example):
    d = kin2grf.info(example / "example_walk.c3d")
    assert d["format"] == "C3D"
    assert d["marker_set"] == {"preset": "kin2grf-example"}
    assert len(d["force_plates"]) == 2
    with pytest.raises(kin2grf.InputError, match="nothing.c3d"):
        kin2grf.info(example / "nothing.c3d")
