"""`viscoadh fit` as a user meets it: the report beside the scene, segment and time-range
options, outputs that are inputs, `fit_file` for batch runners, determinism, and a parameter
the record cannot identify. Records: `fit_records` (independent ``accurate`` model run + 1 %
seeded noise); the fits run the ``fast`` preset; K = 1, so the time-stepped 1D model."""

from __future__ import annotations

import pickle
import re
from pathlib import Path

import numpy as np
import pytest
import yaml
from fit_records import DEPTH_TOPIC, TRUE, scene, standard_history, true_force, write_record, write_scene

from viscoadh_ros.cli.main import main
from viscoadh_ros.core.config import SceneConfig
from viscoadh_ros.experiment import load_experiment
from viscoadh_ros.fitting import FitOptions, fit, fit_file, parameters_of
from viscoadh_ros.io.bag import Bag

#: Start of the fits: every parameter off by 20-40 %.
START = {"G0": 1.3e6, "G1": 1.5e5, "eta1": 2.6e3, "work_of_adhesion": 0.035}


@pytest.fixture(scope="module")
def bag(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("fitcli") / "record.mcap"
    time, depth = standard_history(300)
    write_record(path, time, depth, true_force(TRUE, time, depth), noise=0.01, seed=11)
    return path


def _fit_args(bag: Path, start: Path, out: Path, *extra: str) -> list[str]:
    return ["fit", str(bag), "--scene", str(start), "--depth-topic", DEPTH_TOPIC, "-o", str(out), *extra]


def test_fit_writes_scene_and_report_with_intervals(bag: Path, tmp_path: Path, capsys) -> None:
    start = write_scene(tmp_path / "start.yaml", START)
    out = tmp_path / "results" / "fitted.yaml"
    out.parent.mkdir()  # a verb never creates folders (docs/cli.md)
    assert main(_fit_args(bag, start, out)) == 0
    printed = capsys.readouterr().out
    fitted = parameters_of(SceneConfig.from_yaml(out).contacts[0])
    table = (tmp_path / "results" / "fitted.report.md").read_text()
    for name, truth in TRUE.items():
        row = re.search(rf"^\| {name} \| (\S+) \| (\S+) \.\. (\S+) \|", table, flags=re.MULTILINE)
        assert row, f"{name} missing from the table:\n{table}"
        value, lo, hi = (float(x) for x in row.groups())
        np.testing.assert_allclose(value, fitted[name], rtol=1e-5, err_msg=f"{name}: table vs scene")
        assert lo < value < hi and hi / lo < 1.2, f"{name}: interval {lo:g} .. {hi:g}"
        assert abs(np.log(value / truth)) < 0.05, f"{name}: {value:g} vs truth {truth:g}"
        assert f"{name:>16} = " in printed
    assert re.search(r"RMSE \S+ N against the record's noise level \S+ N \(ratio 0\.9\d", table), table
    png = (tmp_path / "results" / "fitted.report.png").read_bytes()
    assert png[:4] == b"\x89PNG" and len(png) > 20_000, "a real figure"


def test_segment_and_time_range_choose_the_fitted_samples(bag: Path) -> None:
    experiment = load_experiment(Bag(bag), input_topic=DEPTH_TOPIC)
    start = scene(START).contacts[0]
    free = ["G0", "G1", "eta1"]
    approach = fit(start, experiment, free, options=FitOptions(segment="approach"))
    retract = fit(start, experiment, free, options=FitOptions(segment="retract"))
    window = fit(start, experiment, free, options=FitOptions(time_range=(0.0, 0.1)))
    t = experiment.time(experiment.measured_ns)
    depth = np.interp(t, experiment.time(experiment.input_ns), experiment.input_value)
    # The move each sample belongs to: towards the next one (inputs and forces share stamps).
    ahead = np.append(np.diff(depth), 0.0)
    # Each sample belongs to at most one segment; approach samples are where the depth rises.
    assert not np.any(approach.used & retract.used)
    assert np.all(ahead[approach.used] >= -1e-15) and np.all(ahead[retract.used] <= 1e-15)
    assert approach.samples > 80 and retract.samples > 80
    assert np.all(t[window.used] <= 0.1) and window.samples > 100
    # The compressive approach alone fixes the moduli too (w held at its start value, 30 % off,
    # barely acts while pressing in).
    for result in (approach, window):
        for name in free:
            assert abs(np.log(result.values[name] / TRUE[name])) < 0.15, (name, result.values[name])


def test_bad_segment_or_time_range_is_one_error_line(bag: Path, tmp_path: Path, capsys) -> None:
    start = write_scene(tmp_path / "start.yaml", START)
    out = tmp_path / "fitted.yaml"
    for extra, message in (
        (["--time-range", "0.2", "0.1"], "T0 < T1"),
        (["--time-range", "5", "6"], "force samples"),
        # The pull-off (t = 0.17 s) outside what is fitted: w (free by default) cannot be fixed.
        (["--time-range", "0", "0.1"], "work_of_adhesion cannot be identified"),
        (["--segment", "approach"], "work_of_adhesion cannot be identified"),
    ):
        assert main(_fit_args(bag, start, out, *extra)) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and err[0].startswith("viscoadh fit: error: ") and message in err[0], err
        assert not out.exists()


@pytest.mark.parametrize("how", ["same", "dot", "symlink", "scene", "report"])
def test_output_that_is_an_input_is_refused_and_the_input_untouched(
    bag: Path, tmp_path: Path, monkeypatch, capsys, how: str
) -> None:
    monkeypatch.chdir(tmp_path)
    target = write_scene(tmp_path / "input.yaml", START)
    before = target.read_bytes()
    if how == "same":
        out = target
    elif how == "dot":
        out = Path(".") / "sub" / ".." / "input.yaml"
        (tmp_path / "sub").mkdir()
    elif how == "symlink":
        out = tmp_path / "link.yaml"
        out.symlink_to(target)
    elif how == "scene":
        out = Path("./input.yaml")
    else:  # the report of output copy.yaml, copy.report.md, would overwrite the scene input
        target = tmp_path / "copy.report.md"
        target.write_bytes(before)
        out = tmp_path / "copy.yaml"
    code = main(["fit", str(bag), "--scene", str(target), "--depth-topic", DEPTH_TOPIC, "-o", str(out)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and "would overwrite the input" in err[0], err
    assert target.read_bytes() == before, "the input must be untouched"


def test_fit_file_is_a_row_and_never_raises(bag: Path, tmp_path: Path) -> None:
    assert pickle.loads(pickle.dumps(fit_file)) is fit_file, "picklable for Dask workers"
    # G1 and eta1 known (held at the truth), G0 and w fitted.
    start = write_scene(tmp_path / "start.yaml", {**TRUE, "G0": START["G0"], "work_of_adhesion": 0.035})
    options = {"scene": str(start), "depth_topic": DEPTH_TOPIC, "free": "G0,work_of_adhesion"}
    row = fit_file(str(bag), options)
    assert row["status"] == "ok" and row["bag"] == str(bag), row
    for name in ("G0", "work_of_adhesion"):
        assert row[f"{name}_lo95"] < row[name] < row[f"{name}_hi95"]
        assert row[f"{name}_identified"] is True
    assert row["G1"] == TRUE["G1"] and "G1_lo95" not in row, "held parameters are values only"
    assert 0.8 < row["rmse_N"] / row["noise_N"] < 1.3 and row["r2"] > 0.99
    assert row["wall_time_s"] > 0 and row["model_runs"] > 0
    garbage = tmp_path / "garbage.mcap"
    garbage.write_bytes(b"not an mcap file")
    for path, opts in (
        (str(garbage), options),
        (str(tmp_path / "missing.mcap"), options),
        (str(bag), {**options, "free": "G7"}),
        (str(bag), {**options, "nonsense": 1}),
    ):
        failed = fit_file(path, opts)
        assert failed["status"] == "failed" and failed["reason"], failed
        assert "\n" not in failed["reason"]


def test_same_record_and_options_give_the_same_numbers(bag: Path, tmp_path: Path) -> None:
    start = write_scene(tmp_path / "start.yaml", START)
    options = {"scene": str(start), "depth_topic": DEPTH_TOPIC}
    first = fit_file(str(bag), options)
    other = tmp_path / "other.mcap"
    time, depth = standard_history(120)
    write_record(other, time, depth, true_force(TRUE, time, depth), noise=0.03, seed=5)
    fit_file(str(other), options)  # whatever was fitted before
    again = fit_file(str(bag), options)
    for key in first:
        if key not in ("wall_time_s",):
            assert first[key] == again[key], key


def test_a_parameter_the_record_cannot_fix_is_an_interval(tmp_path: Path, capsys) -> None:
    """A record 100x slower than the relaxation: no loading as fast as it, so the viscosity
    is not identified; the fit says so and gives its interval, which holds the truth."""
    time, depth = standard_history(200)
    time = time * 100.0
    path = tmp_path / "slow.mcap"
    write_record(path, time, depth, true_force(TRUE, time, depth), noise=0.01, seed=3)
    start = write_scene(tmp_path / "start.yaml", START)
    out = tmp_path / "fitted.yaml"
    assert main(_fit_args(path, start, out)) == 0
    printed = capsys.readouterr().out
    assert re.search(r"eta1\s+NOT IDENTIFIED: 95% (\S+) \.\. (\S+) Pa s", printed), printed
    lo, hi = (float(x) for x in re.search(r"eta1\s+NOT IDENTIFIED: 95% (\S+) \.\. (\S+)", printed).groups())
    assert lo <= TRUE["eta1"] <= hi and hi / lo > 3, (lo, hi)
    assert "not identified" in printed
    table = yaml.safe_load(out.read_text())  # the scene is still written (best values)
    assert table


def test_the_not_identified_verdict_survives_rounding_noise(tmp_path: Path, capsys, monkeypatch) -> None:
    """The same slow record with the model's force perturbed at 1e-13 of its largest value,
    pseudo-randomly and differently for every parameter value (as a change of the kernel's
    summation order would): the viscosity's finite-difference sensitivity is then rounding
    noise, and the verdict must not follow it (0.4.0 found a four-lane Simpson sum, <= 4e-15 of
    the force, turning NOT IDENTIFIED into a confident 26 % error bar)."""
    from viscoadh_ros.core.simulator import ContactSimulator

    exact = ContactSimulator._step_depths

    def rounded(self, times, depths):
        columns = exact(self, times, depths)
        force = columns["force"]
        scale = float(np.max(np.abs(force))) or 1.0
        # The fraction of a high multiple of each value: changes with the last bits of the force.
        noise = np.modf(np.abs(force) * 2.0**36 / scale + np.arange(force.size) * 0.618)[0] - 0.5
        columns["force"] = force + 2e-13 * scale * noise
        return columns

    monkeypatch.setattr(ContactSimulator, "_step_depths", rounded)
    time, depth = standard_history(200)
    time = time * 100.0
    path = tmp_path / "slow.mcap"
    write_record(path, time, depth, true_force(TRUE, time, depth), noise=0.01, seed=3)
    start = write_scene(tmp_path / "start.yaml", START)
    assert main(_fit_args(path, start, tmp_path / "fitted.yaml")) == 0
    printed = capsys.readouterr().out
    found = re.search(r"eta1\s+NOT IDENTIFIED: 95% (\S+) \.\. (\S+) Pa s", printed)
    assert found, printed
    lo, hi = (float(x) for x in found.groups())
    assert lo <= TRUE["eta1"] <= hi, (lo, hi)


def test_a_curved_valley_widens_the_interval_to_the_truth(tmp_path: Path) -> None:
    """The standard history squeezed into 2 ms (the Kelvin element, retardation 10 ms, only
    starts to creep): G1 and eta1 trade off along a curved valley (G1 from 22 to 290 kPa while
    eta1 goes from 2100 to 1950 Pa s at nearly the same cost). From a start off by 1.3-2x the fit
    stops at G1 = 74 kPa, eta1 = 2074; the linear profile direction leaves the valley, and 0.4.0
    stated eta1 95 % 2059 .. 2115, excluding the truth (2000) that the profile puts 1.3 noise
    variances above the minimum. Found by an outside tester (benchmarks/outside_test_0.5.0).
    0.5.0 still stated G1 identified, 33 .. 166 kPa, where its profile (the others descended to
    the valley's floor) stays below 1.2 noise variances from 10 to 200 kPa: the profile check
    now finds each end where the profile rises to the 95 % level, and G1 is not identified."""
    time, depth = standard_history(1000)
    time = time / 100.0
    path = tmp_path / "glassy.mcap"
    write_record(path, time, depth, true_force(TRUE, time, depth), noise=0.01, seed=100)
    factors = {"G0": 1.5, "G1": 0.5, "eta1": 2.0, "work_of_adhesion": 1.3}
    start = write_scene(tmp_path / "start.yaml", {k: TRUE[k] * f for k, f in factors.items()})
    row = fit_file(str(path), {"scene": str(start), "depth_topic": DEPTH_TOPIC})
    assert row["status"] in ("ok", "unidentified"), row
    for name in ("G0", "G1", "eta1", "work_of_adhesion"):
        assert row[f"{name}_lo95"] <= TRUE[name] <= row[f"{name}_hi95"], (name, row)
    assert not row["G1_identified"], row
    assert row["status"] == "unidentified", row


@pytest.mark.parametrize("after", [1, 3, 40])
def test_a_record_ending_at_or_right_after_its_most_tensile_sample_is_an_input_error(
    tmp_path: Path, capsys, after: int
) -> None:
    """A pull recorded up to the pull-off but not past it (outside tester: 0.5.0 exited 1 with
    a ValueError traceback from has_pull_off's convolution of nothing): no pull-off is seen, so
    the work of adhesion cannot be fitted, and the fit says so (exit 2). A record that goes on
    past the pull-off (40 samples) fits."""
    from viscoadh_ros.fitting import has_pull_off

    time, depth = standard_history(400)
    force = true_force(TRUE, time, depth)
    end = int(np.argmin(force)) + after
    assert not has_pull_off(force[: int(np.argmin(force)) + 1])
    path = tmp_path / "cut.mcap"
    write_record(path, time[:end], depth[:end], force[:end], noise=0.0, seed=1)
    start = write_scene(tmp_path / "start.yaml", TRUE)
    code = main(_fit_args(path, start, tmp_path / "fitted.yaml"))
    err = capsys.readouterr().err
    if after < 40:
        assert code == 2, err
        assert "pull-off" in err and "Traceback" not in err, err
    else:
        assert code == 0, err


def test_a_record_with_a_depth_beyond_the_scene_is_an_input_error_naming_it(tmp_path: Path, capsys) -> None:
    """One sample at 1e4 m (beyond the largest domain, refused by every model run since 0.8.0):
    the fit ran into refused trials and reported a secant that would not converge (0.8.0's
    outside tester). It now names the sample before fitting, as replay does."""
    time, depth = standard_history(200)
    force = true_force(TRUE, time, depth)
    depth = depth.copy()
    depth[80] = 1e4
    path = tmp_path / "deep.mcap"
    write_record(path, time, depth, force, noise=0.01, seed=2)
    start = write_scene(tmp_path / "start.yaml", TRUE)
    code = main(_fit_args(path, start, tmp_path / "fitted.yaml"))
    err = capsys.readouterr().err.strip()
    assert code == 2 and "depth[80]: 10000.0 m is beyond the scene's range" in err and "\n" not in err, err
    assert not (tmp_path / "fitted.yaml").exists()
