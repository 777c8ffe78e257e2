import os
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
SHARED = ROOT.parent / "shared" / "data"


@pytest.fixture
def rng():
    """A seeded generator: every random test is repeatable."""
    return np.random.default_rng(20261121)


@pytest.fixture
def shared_data():
    """Path to ../shared/data; under CI a missing folder fails the test instead of skipping it."""
    def get(rel: str) -> Path:
        p = SHARED / rel
        if not p.exists():
            if os.environ.get("CI"):
                pytest.fail(f"shared data {p} is missing under CI")
            pytest.skip(f"shared data {p} not present")
        return p
    return get


@pytest.fixture
def sample_dir():
    return ROOT / "sample_data"


def _pg_bin(name: str):
    """A PostgreSQL server program: on PATH, or in Debian's /usr/lib/postgresql/<version>/bin."""
    import glob
    import shutil
    found = shutil.which(name)
    if found:
        return found
    hits = sorted(glob.glob(f"/usr/lib/postgresql/*/bin/{name}"))
    return hits[-1] if hits else None


@pytest.fixture(scope="session")
def postgres():
    """A throw-away PostgreSQL cluster on 127.0.0.1 (Debian's postgresql package: .ci/run installs it),
    started for this test session and stopped after it. Yields a function that creates a fresh, empty
    database and returns its URL. Under CI a missing server fails instead of skipping."""
    import shutil
    import socket
    import subprocess
    initdb, pg_ctl = _pg_bin("initdb"), _pg_bin("pg_ctl")
    if initdb is None or pg_ctl is None:
        if os.environ.get("CI"):
            pytest.fail("PostgreSQL (initdb, pg_ctl) is missing under CI: .ci/run installs Debian's postgresql")
        pytest.skip("PostgreSQL server programs not installed")
    import tempfile
    # its own folder under the system's temporary directory: pytest's is private to this user, and the
    # server runs as its own user when the tests run as root
    base = Path(tempfile.mkdtemp(prefix="vibmeasure-pg-"))
    data, sock = base / "data", base / "sock"
    sock.mkdir()
    as_user = []
    if os.geteuid() == 0:   # the server refuses to run as root: its own system user runs it
        shutil.chown(base, "postgres")
        shutil.chown(sock, "postgres")
        os.chmod(base, 0o755)
        as_user = ["runuser", "-u", "postgres", "--"]
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    subprocess.run(as_user + [initdb, "-D", str(data), "-A", "trust", "-U", "vibmeasure", "--no-sync", "-E", "UTF8"],
                   check=True, capture_output=True)
    opts = f"-c listen_addresses=127.0.0.1 -p {port} -k {sock} -c fsync=off -c max_connections=60"
    subprocess.run(as_user + [pg_ctl, "-D", str(data), "-o", opts, "-l", str(base / "log"), "-w", "start"],
                   check=True, capture_output=True)
    import psycopg
    admin = f"postgresql://vibmeasure@127.0.0.1:{port}/postgres"
    count = iter(range(10 ** 6))

    def fresh() -> str:
        name = f"t{next(count)}"
        with psycopg.connect(admin, autocommit=True) as c:
            c.execute(f"CREATE DATABASE {name}")
        return f"postgresql://vibmeasure@127.0.0.1:{port}/{name}"
    try:
        yield fresh
    finally:
        subprocess.run(as_user + [pg_ctl, "-D", str(data), "-m", "immediate", "stop"], capture_output=True)
        shutil.rmtree(base, ignore_errors=True)
