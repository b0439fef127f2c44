"""Two `tune` workers on one study in a throwaway PostgreSQL cluster (Debian's server, a free local port, a temporary
directory, run as the `postgres` system user when the test runs as root). SKIPPED only if the server cannot start."""
import glob
import os
import pwd
import shutil
import socket
import subprocess
import sys
import tempfile
import time
import warnings

import optuna
import pytest

from conftest import TUNE, bin_dir, run_tune, write_drive_set

pytestmark = pytest.mark.filterwarnings("ignore::optuna.exceptions.ExperimentalWarning")
warnings.filterwarnings("ignore", message=".*experimental.*")


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Cluster:
    def __init__(self):
        bins = sorted(glob.glob("/usr/lib/postgresql/*/bin/initdb"))
        if not bins:
            raise RuntimeError("no initdb (Debian package postgresql)")
        self.bin = os.path.dirname(bins[-1])
        self.dir = tempfile.mkdtemp(prefix="maf_pg_")
        self.data = os.path.join(self.dir, "data")
        self.port = free_port()
        self.as_user = []
        if os.geteuid() == 0:  # PostgreSQL refuses to run as root
            try:
                pw = pwd.getpwnam("postgres")
            except KeyError:
                raise RuntimeError("running as root and there is no 'postgres' user")
            os.chown(self.dir, pw.pw_uid, pw.pw_gid)
            self.as_user = ["runuser", "-u", "postgres", "--"]

    def run(self, *cmd, timeout=60):
        r = subprocess.run(self.as_user + list(cmd), capture_output=True, text=True, timeout=timeout)
        if r.returncode != 0:
            raise RuntimeError(f"{os.path.basename(cmd[0])}: {(r.stderr or r.stdout).strip().splitlines()[-1:]}")
        return r

    def start(self):
        self.run(os.path.join(self.bin, "initdb"), "-D", self.data, "-A", "trust", "-U", "postgres", "--no-sync")
        self.run(os.path.join(self.bin, "pg_ctl"), "-D", self.data, "-l", os.path.join(self.dir, "log"), "-w", "-t", "60",
                 "-o", f"-p {self.port} -k {self.dir} -c listen_addresses=127.0.0.1 -c fsync=off", "start")
        self.run(os.path.join(self.bin, "createdb"), "-h", "127.0.0.1", "-p", str(self.port), "-U", "postgres", "maf")
        return f"postgresql://postgres@127.0.0.1:{self.port}/maf"

    def stop(self):
        subprocess.run(self.as_user + [os.path.join(self.bin, "pg_ctl"), "-D", self.data, "-m", "immediate", "-w",
                                       "stop"], capture_output=True, timeout=60)
        shutil.rmtree(self.dir, ignore_errors=True)


@pytest.fixture
def postgres():
    try:
        cluster = Cluster()
    except RuntimeError as e:
        pytest.skip(f"SKIPPED: PostgreSQL cannot start: {e}")
    try:
        url = cluster.start()
    except (RuntimeError, subprocess.TimeoutExpired) as e:
        cluster.stop()
        pytest.skip(f"SKIPPED: PostgreSQL cannot start: {e}")
    yield url
    cluster.stop()
    assert not os.path.exists(cluster.dir)


def test_two_workers_share_one_study_in_postgresql(postgres, tools, tmp_path):
    ds = write_drive_set(str(tmp_path / "drives.yaml"), training=[("town", 1, "ibeo4"), ("village", 1, "ibeo4")])
    work = ["--work", str(tmp_path / "work")]
    # the bags and the tables first, so that both workers start trials at about the same time
    warm = run_tune(["--drives", ds, "--storage", postgres, "--study", "warm", "--trials", "1"] + work)
    assert warm.returncode == 0, warm.stdout + warm.stderr
    cmd = [sys.executable, TUNE, "--drives", ds, "--storage", postgres, "--study", "shared", "--trials", "6",
           "--jobs", "1"] + work
    procs = []
    for k in range(2):
        procs.append(subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                      env=dict(os.environ, MAF_BIN=bin_dir())))
        if k == 0:
            time.sleep(1.0)  # the first creates the study
    outs = [p.communicate(timeout=600) for p in procs]
    for p, (out, err) in zip(procs, outs):
        assert p.returncode == 0, out + err
    st = optuna.load_study(study_name="shared", storage=postgres)
    done = [t for t in st.trials if t.state.is_finished()]
    assert 6 <= len(done) <= 7  # two workers may both start the last trial
    pids = {t.user_attrs["worker"] for t in done}
    assert len(pids) == 2, pids  # both workers' trials landed in the one study
    assert [t.number for t in st.trials] == list(range(len(st.trials)))
