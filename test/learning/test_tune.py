"""learning/tune on two short drives with file storage: a 6-trial study that resumes, trials that crash or time out
recorded as failed, interrupted trials, the report, and the one-line errors of bad input."""
import os
import shutil
import socket
import stat
import subprocess
import sys
import warnings

import optuna
import pytest
import yaml

from conftest import ROOT, bin_dir, run_tune, write_drive_set
from maf_learning import objective, space

pytestmark = pytest.mark.filterwarnings("ignore::optuna.exceptions.ExperimentalWarning")
warnings.filterwarnings("ignore", message=".*experimental.*")
optuna.logging.set_verbosity(optuna.logging.WARNING)


def journal(path):
    return optuna.storages.JournalStorage(optuna.storages.JournalFileStorage(str(path)))


def finished(study):
    return [t for t in study.trials if t.state.is_finished()]


@pytest.fixture(scope="module")
def study_dir(tmp_path_factory, tools):
    """A 6-trial study, run as 3 trials and then resumed to 6."""
    d = tmp_path_factory.mktemp("tune")
    ds = write_drive_set(str(d / "drives.yaml"))
    args = ["--drives", ds, "--work", str(d / "work"), "--seed", "3", "--study", "s"]
    first = run_tune(args + ["--trials", "3", "--jobs", "1"])
    assert first.returncode == 0, first.stdout + first.stderr
    st = optuna.load_study(study_name="s", storage=journal(d / "work" / "s.journal"))
    before = {t.number: (t.params, t.value, t.state) for t in finished(st)}
    second = run_tune(args + ["--trials", "6", "--jobs", "2"])
    assert second.returncode == 0, second.stdout + second.stderr
    return d, args, before, first.stdout, second.stdout


def test_six_trial_study_resumes_without_losing_trials(study_dir):
    d, _, before, out1, out2 = study_dir
    assert len(before) == 3
    st = optuna.load_study(study_name="s", storage=journal(d / "work" / "s.journal"))
    done = finished(st)
    assert len(done) == 6
    for t in done:
        if t.number in before:
            assert (t.params, t.value, t.state) == before[t.number]
    assert "3 trial(s) already, target 6" in out2
    assert "trials:" in out1 and "best" in out1  # the progress display
    # trial 0 is the configuration of config/, scored like any other
    assert st.trials[0].user_attrs.get("seeded") == "config/"
    base = space.base_values(os.path.join(ROOT, "config"))
    assert st.trials[0].params["fusion.alpha_dynamic"] == base["fusion.yaml"]["alpha_dynamic"]
    complete = [t for t in done if t.state == optuna.trial.TrialState.COMPLETE]
    assert complete
    for t in complete:
        s = t.user_attrs["scores"]
        assert 0.0 <= s["mean_iou"] <= 1.0 and 0.0 <= s["v_precision"] <= 1.0
        assert t.value == pytest.approx(objective.score(s, st.user_attrs["reference"][-1]))
        assert len(t.intermediate_values) == 2  # one per training drive
    # a rerun with the target reached runs nothing
    r = run_tune(study_dir[1] + ["--trials", "6"])
    assert r.returncode == 0 and "6 trial(s) already" in r.stdout
    assert len(finished(optuna.load_study(study_name="s", storage=journal(d / "work" / "s.journal")))) == 6


def test_interrupted_trials_are_recorded_failed_and_not_counted(study_dir, tmp_path):
    d, args, _, _, _ = study_dir
    storage = journal(d / "work" / "s.journal")
    st = optuna.load_study(study_name="s", storage=storage)
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    t = st.ask()
    storage.set_trial_user_attr(t._trial_id, "worker", f"{socket.gethostname()}:{dead.pid}")
    r = run_tune(args + ["--trials", "7", "--jobs", "1"])
    assert r.returncode == 0, r.stderr
    assert "interrupted earlier are recorded as failed" in r.stdout
    st = optuna.load_study(study_name="s", storage=journal(d / "work" / "s.journal"))
    stale = st.trials[t.number]
    assert stale.state == optuna.trial.TrialState.FAIL and stale.user_attrs.get("interrupted")
    assert len([x for x in finished(st) if not x.user_attrs.get("interrupted")]) == 7


def test_report_writes_the_learned_profile_and_the_table(study_dir, tools):
    d, args, _, _, _ = study_dir
    out = d / "learned"
    table = d / "report.md"
    r = run_tune(args + ["--report", "--profile-out", str(out), "--table", str(table)], timeout=900)
    assert r.returncode == 0, r.stdout + r.stderr
    st = optuna.load_study(study_name="s", storage=journal(d / "work" / "s.journal"))
    best = max((t for t in st.trials if t.state == optuna.trial.TrialState.COMPLETE), key=lambda t: t.value)
    fusion = yaml.safe_load((out / "fusion.yaml").read_text())
    assert fusion["alpha_dynamic"] == pytest.approx(best.params["fusion.alpha_dynamic"], abs=1e-6)
    ibeo = yaml.safe_load((out / "ibeo" / "scan_grid.yaml").read_text())
    assert ibeo["ground_model"] == "flat" and ibeo["relative_height_limit"] == 0.0  # the sensor's lines kept
    assert ibeo["mu_free"] == pytest.approx(best.params["scan_grid.mu_free"], abs=1e-6)
    ibeo_fusion = yaml.safe_load((out / "ibeo" / "fusion.yaml").read_text())
    assert ibeo_fusion["tracker_min_cluster_points"] == 4  # the sensor's line kept
    assert ibeo_fusion["alpha_dynamic"] == pytest.approx(best.params["fusion.alpha_dynamic"], abs=1e-6)
    assert space.check_config_dir(tools["evaluate"], str(out)) is None
    text = table.read_text()
    for row in ("| training | paper's method", "| held-out | learned profile", "Dempster's rule", "Held-out verdict",
                "## Moving objects (pooled per split", "| held-out | default profile (`config/`) |"):
        assert row in text, row


def fake_evaluate(tmp_path, body):
    """An evaluate that runs the real one except for the tuned (`--only default`) runs, where it does `body`."""
    p = tmp_path / "evaluate"
    p.write_text("#!/bin/sh\ncase \"$*\" in *'--only default'*) " + body + " ;; esac\n"
                 f"exec {os.path.join(bin_dir(), 'evaluate')} \"$@\"\n")
    p.chmod(p.stat().st_mode | stat.S_IEXEC)
    return str(p)


@pytest.mark.parametrize("body,why", [("echo 'evaluate: boom' >&2; exit 1", "failed"),
                                      ("kill -SEGV $$", "failed"), ("sleep 30", "timed out")])
def test_a_trial_that_crashes_or_times_out_is_failed_never_scored(tmp_path, tools, body, why):
    ds = write_drive_set(str(tmp_path / "drives.yaml"), training=[("town", 1, "ibeo4")])
    r = run_tune(["--drives", ds, "--work", str(tmp_path / "work"), "--study", "f", "--trials", "2", "--jobs", "1",
                  "--trial-timeout", "3", "--evaluate", fake_evaluate(tmp_path, body)])
    assert r.returncode == 0, r.stdout + r.stderr
    st = optuna.load_study(study_name="f", storage=journal(tmp_path / "work" / "f.journal"))
    assert [t.state for t in st.trials] == [optuna.trial.TrialState.FAIL] * 2
    for t in st.trials:
        assert t.value is None and why in t.user_attrs["failure"]


def one_line_error(r):
    lines = [ln for ln in r.stderr.splitlines() if ln.strip()]
    assert r.returncode == 2, r.stdout + r.stderr
    assert len(lines) == 1, r.stderr
    return lines[0]


def test_unreachable_storage_is_a_one_line_error(tmp_path):
    ds = write_drive_set(str(tmp_path / "drives.yaml"), training=[("town", 1, "ibeo4")])
    r = run_tune(["--drives", ds, "--work", str(tmp_path / "w"), "--storage", "postgresql://maf:secret@127.0.0.1:1/maf",
                  "--trials", "1"], timeout=120)
    line = one_line_error(r)
    assert line.startswith("tune: storage postgresql://maf:***@127.0.0.1:1/maf: cannot open it")
    assert not list((tmp_path / "w").rglob("*.bag")), "drives simulated before the storage was reached"
    r = run_tune(["--drives", ds, "--work", str(tmp_path / "w"), "--storage", "mysql://x/y", "--trials", "1"])
    assert "unknown kind" in one_line_error(r)


def test_unknown_scenario_key_is_a_one_line_error(tmp_path):
    p = tmp_path / "drives.yaml"
    p.write_text("training:\n  - {template: town, seed: 1, speed: 3}\n")
    assert "training[0]: unknown key 'speed'" in one_line_error(run_tune(["--drives", str(p), "--work", str(tmp_path)]))
    p.write_text("training:\n  - {template: suburb, seed: 1}\n")
    assert "template 'suburb'" in one_line_error(run_tune(["--drives", str(p), "--work", str(tmp_path)]))


@pytest.mark.parametrize("text,named", [
    ("fusion.yaml: {alpha_static: [0.2, 0.1]}\n", "fusion.yaml: alpha_static: the range [0.2, 0.1] is empty"),
    ("fusion.yaml: {alpha_static: [0.0, 2.0]}\n", "fusion.yaml: alpha_static: [0.0, 2.0] leaves the valid interval"),
    ("scan_grid.yaml: {mu_free: [-0.5, 0.5]}\n", "scan_grid.yaml: mu_free: [-0.5, 0.5] leaves the valid interval"),
    ("fusion.yaml: {combination_rule: {choices: [modified_yager, murphy]}}\n", "combination_rule"),
    ("fusion.yaml: {alpha_statc: [0.0, 0.1]}\n", "alpha_statc: not a parameter of config/fusion.yaml"),
    ("fusions.yaml: {alpha_static: [0.0, 0.1]}\n", "'fusions.yaml' is not a configuration file"),
    ("fusion.yaml: 5\n", "fusion.yaml: must map parameters to ranges"),
    ("[alpha_static, 0.1]\n", "must map config files to parameters"),
])
def test_bad_search_space_is_a_one_line_error_naming_the_parameter(tmp_path, tools, text, named):
    ds = write_drive_set(str(tmp_path / "drives.yaml"), training=[("town", 1, "ibeo4")])
    sp = tmp_path / "space.yaml"
    sp.write_text(text)
    line = one_line_error(run_tune(["--drives", ds, "--space", str(sp), "--work", str(tmp_path / "w")]))
    assert named in line, line


def test_refresh_profile_renders_the_learned_values_over_the_current_configuration(tmp_path, tools):
    """A profile written before config/ gained a key (the tracker's) or changed one (the ScanGrid's size) becomes every
    key of config/ again, with its learned values, its header and the IBEO sensor's lines kept."""
    prof = tmp_path / "learned"
    shutil.copytree(os.path.join(ROOT, "config", "learned"), prof)
    learned_before = space.base_values(str(prof))
    fusion_text = (prof / "fusion.yaml").read_text()
    header = "".join(fusion_text.splitlines(keepends=True)[:2])
    # Age it: drop a key config/ has, change one no study learns.
    (prof / "fusion.yaml").write_text("".join(ln for ln in fusion_text.splitlines(keepends=True)
                                              if not ln.startswith("tracker_gate:")))
    scan = (prof / "scan_grid.yaml").read_text()
    (prof / "scan_grid.yaml").write_text(scan.replace("\ngrid_size_x:", "\ngrid_size_x: 77.0 #", 1))
    r = run_tune(["--refresh-profile", "--profile-out", str(prof)])
    assert r.returncode == 0, r.stdout + r.stderr
    config = space.base_values(os.path.join(ROOT, "config"))
    after = space.base_values(str(prof))
    learned_keys = {(p.file, p.name) for p in space.load_space(os.path.join(ROOT, "learning", "search_space.yaml"))}
    for file, values in config.items():
        assert set(after[file]) == set(values), file
        for key, value in values.items():
            expected = learned_before[file][key] if (file, key) in learned_keys else value
            if isinstance(value, float):
                expected = pytest.approx(expected, abs=1e-6)
            assert after[file][key] == expected, (file, key)
    assert (prof / "fusion.yaml").read_text().startswith(header)
    ibeo = yaml.safe_load((prof / "ibeo" / "scan_grid.yaml").read_text())
    assert ibeo["ground_model"] == "flat" and ibeo["relative_height_limit"] == 0.0  # the sensor's lines kept
    assert ibeo["mu_free"] == pytest.approx(learned_before["scan_grid.yaml"]["mu_free"], abs=1e-6)
    ibeo_fusion = yaml.safe_load((prof / "ibeo" / "fusion.yaml").read_text())
    assert ibeo_fusion["tracker_min_cluster_points"] == 4  # the sensor's line kept
    assert ibeo_fusion["alpha_dynamic"] == pytest.approx(learned_before["fusion.yaml"]["alpha_dynamic"], abs=1e-6)
    assert space.check_config_dir(tools["evaluate"], str(prof)) is None


def test_refresh_profile_without_a_learned_header_is_a_one_line_error(tmp_path):
    prof = tmp_path / "learned"
    shutil.copytree(os.path.join(ROOT, "config", "learned"), prof)
    (prof / "fusion.yaml").write_text((prof / "fusion.yaml").read_text().split("\n", 2)[2])
    assert "does not start with the header" in one_line_error(run_tune(["--refresh-profile", "--profile-out", str(prof)]))
