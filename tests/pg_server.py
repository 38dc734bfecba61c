"""A throw-away PostgreSQL server for tests: Debian's binaries, a temporary folder, a free port.

``initdb`` refuses to run as root, so under root the server runs as the ``postgres`` system user
(created by Debian's ``postgresql`` package). ``.ci/run`` installs the package when it is missing.
"""

from __future__ import annotations

import contextlib
import glob
import os
import pwd
import shutil
import socket
import subprocess
import tempfile
import uuid
from collections.abc import Iterator
from pathlib import Path


def server_binaries() -> Path | None:
    """Folder with initdb and pg_ctl (PATH first, then /usr/lib/postgresql/<version>/bin)."""
    found = shutil.which("initdb")
    if found and shutil.which("pg_ctl"):
        return Path(found).resolve().parent
    candidates = sorted(glob.glob("/usr/lib/postgresql/*/bin/initdb"), reverse=True)
    return Path(candidates[0]).parent if candidates else None


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


@contextlib.contextmanager
def postgresql_server() -> Iterator[str]:
    """Start a server; yield the URL of its maintenance database; stop and delete it afterwards.

    Raises RuntimeError with the reason when no server can be started.
    """
    bindir = server_binaries()
    if bindir is None:
        raise RuntimeError("PostgreSQL server binaries not found (apt-get install -y postgresql)")
    user: str | None = None
    if os.geteuid() == 0:
        try:
            pwd.getpwnam("postgres")
        except KeyError:
            raise RuntimeError("running as root and there is no 'postgres' user to run the server as") from None
        user = "postgres"
    root = Path(tempfile.mkdtemp(prefix="abrupt-pg-"))
    data = root / "data"
    if user is not None:
        info = pwd.getpwnam(user)
        os.chown(root, info.pw_uid, info.pw_gid)
    port = _free_port()

    def run(*args: str) -> subprocess.CompletedProcess[str]:
        return subprocess.run(list(args), user=user, capture_output=True, text=True, timeout=120, check=False)

    try:
        done = run(
            str(bindir / "initdb"), "-D", str(data), "-A", "trust", "-U", "abrupt", "-E", "UTF8", "--locale=C", "-N"
        )
        if done.returncode != 0:
            raise RuntimeError(f"initdb failed: {done.stderr.strip().splitlines()[-1:]}")
        opts = f"-p {port} -k {root} -c listen_addresses=127.0.0.1 -c fsync=off -c max_connections=50"
        done = run(str(bindir / "pg_ctl"), "-D", str(data), "-o", opts, "-l", str(root / "log"), "-w", "start")
        if done.returncode != 0:
            log = (root / "log").read_text(errors="replace") if (root / "log").exists() else done.stderr
            raise RuntimeError(f"pg_ctl start failed: {log.strip().splitlines()[-1:]}")
        yield f"postgresql://abrupt@127.0.0.1:{port}/postgres"
    finally:
        if data.exists():
            run(str(bindir / "pg_ctl"), "-D", str(data), "-m", "immediate", "-w", "stop")
        shutil.rmtree(root, ignore_errors=True)


def new_database(server_url: str) -> str:
    """Create an empty database on the server; return its URL."""
    import psycopg

    name = "t_" + uuid.uuid4().hex[:12]
    with psycopg.connect(server_url.replace("postgresql://", "postgresql://", 1), autocommit=True) as conn:
        conn.execute(f'CREATE DATABASE "{name}"')
    return server_url.rsplit("/", 1)[0] + "/" + name
