"""Cases of the adversarial audit (``benchmarks/bench_audit_cases.py``) that had no test of their own.

GRG DORIS products of Jason-2 (2008) and TOPEX (1997) write velocities in m/s where SP3 asks dm/s; their
files are not beside the project, so a proxy is written with their header and record layout (SP3-c,
``DORIS ITR05 FIT  LCA``, LEO file type, TAI, 60 s) around a simulated two-body + J2 orbit of the same
shape (the independent truth): it must read with the rescale counted at every epoch and the truth's
velocities restored, and detection on it must give no event.
"""

from __future__ import annotations

import os
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from _audit_cases import THESIS_TOML, itrf, truth_orbit
from _audit_door_cases import _tumbling
from _audit_orbit_cases import grg_proxy
from abrupt.cli.commands import cli
from abrupt.cli.main import main
from abrupt.errors import InputError
from abrupt.pipelines.orbit import detect_orbit
from abrupt.readers.ephemeris import read_ephemeris
from abrupt.readers.navigation_csv import write_navigation_csv
from abrupt.readers.orbit_envelope import PV_MISMATCH_REPAIR, power_of_ten_repair


@pytest.mark.parametrize(
    ("satellite", "epoch_utc", "name"),
    [
        ("L27", "2008-08-30T20:59:27", "grgja203.b08243.e08243.D_S.sp3"),
        ("L01", "1997-12-10T11:59:29", "grgtop03.b97344.e97344.D_S.sp3"),
    ],
)
def test_a_grg_doris_product_with_velocities_in_m_per_s_is_rescaled_and_counted(
    satellite: str, epoch_utc: str, name: str, tmp_path: Path
) -> None:
    path = grg_proxy(tmp_path, satellite, epoch_utc, name, hours=3.0)
    first = path.read_text().splitlines()[0]
    assert first.startswith("#cV") and first.endswith("DORIS ITR05 FIT  LCA")
    truth = itrf(truth_orbit(hours=3.0, epoch=epoch_utc, satellite=satellite))
    eph = read_ephemeris(path)
    assert eph.repairs.counts[power_of_ten_repair(1)] == len(truth) == len(eph)
    np.testing.assert_allclose(eph.position_m, truth.position_m, rtol=0, atol=1e-3)  # the file keeps mm
    # m/s with 6 decimals in the file: 1e-6 m/s, times 10 once rescaled
    np.testing.assert_allclose(eph.velocity_mps, truth.velocity_mps, rtol=0, atol=2e-5)
    seconds = (eph.times_utc - truth.times_utc).astype("timedelta64[ns]").astype(np.int64)
    assert np.abs(seconds).max() < 1_000  # TAI epochs back to the UTC of the truth


def test_detection_on_a_grg_proxy_gives_no_event(tmp_path: Path) -> None:
    path = grg_proxy(tmp_path, "L27", "2008-08-30T20:59:27", "grgja203.b08243.e08244.D_S.sp3", hours=12.0)
    run = detect_orbit(path)
    assert len(run.events) == 0
    assert run.result.diagnostics and not any("nothing tested" in w for w in run.result.warnings)


@pytest.mark.parametrize("order", [[1, 0, 2], [0, 2, 1]])
def test_position_columns_in_the_wrong_order_are_refused_not_emptied(order: list[int], tmp_path: Path) -> None:
    """x and y (or y and z) position columns swapped, the velocities left: the median speed still agrees,
    but the velocities point elsewhere at nearly every epoch. Refused (it once removed all 721 epochs
    as mismatched, leaving a run that tested nothing with exit 0)."""
    truth = truth_orbit(hours=3.0)
    path = tmp_path / "swapped.csv"
    write_navigation_csv(replace(truth, position_m=truth.position_m[:, order]), path)
    with pytest.raises(InputError, match=r"velocity = derivative of position.*columns in the wrong order") as info:
        read_ephemeris(path)
    assert "swapped.csv" in str(info.value) and "\n" not in str(info.value)


def test_a_few_mismatched_velocities_are_still_removed_and_counted(tmp_path: Path) -> None:
    truth = truth_orbit(hours=3.0)
    vel = truth.velocity_mps.copy()
    vel[[40, 90]] *= -1.0  # two records' velocities reversed: 6 of 181 epochs removed with their neighbours
    path = tmp_path / "two.csv"
    write_navigation_csv(replace(truth, velocity_mps=vel), path)
    eph = read_ephemeris(path)
    assert eph.repairs.counts[PV_MISMATCH_REPAIR] == 6 and len(eph) == len(truth) - 6


def test_running_out_of_memory_is_one_line(capsys: pytest.CaptureFixture[str]) -> None:
    @cli.command("exhaust", hidden=True)
    def exhaust() -> None:
        raise MemoryError("Unable to allocate 229. MiB for an array with shape (10000000, 3) and data type float64")

    try:
        with pytest.raises(SystemExit) as info:
            main(["exhaust"])
    finally:
        cli.commands.pop("exhaust")
    assert info.value.code == 2
    assert capsys.readouterr().err.splitlines() == [
        "error: not enough memory for this run (Unable to allocate 229. MiB for an array with shape (10000000, 3) "
        "and data type float64)"
    ]


@pytest.mark.parametrize(
    ("argv", "says"),
    [
        (["simulate", "population", "--count", "-5"], "Invalid value for '--count': -5 is not in the range x>=1."),
        (["detect", "tle", "--bogus", "x"], "No such option '--bogus'."),
    ],
)
def test_a_wrong_option_is_one_error_line_naming_the_help(
    argv: list[str], says: str, capsys: pytest.CaptureFixture[str]
) -> None:
    with pytest.raises(SystemExit) as info:
        main(argv)
    err = capsys.readouterr().err.splitlines()
    assert info.value.code == 2 and len(err) == 1, err
    assert err[0].startswith("error: ") and says in err[0] and f"(options: abrupt {' '.join(argv[:2])} -h)" in err[0]


PEAK = (
    "import atexit, sys\n"
    "def peak():\n"
    "    status = open('/proc/self/status').read()\n"
    "    print('VmPeak', status.split('VmPeak:')[1].split()[0], file=sys.stderr)\n"
    "atexit.register(peak)\n"
    "from abrupt.cli.main import main\n"
    "main(sys.argv[1:])\n"
)


@pytest.mark.skipif(not Path("/proc/self/status").exists(), reason="needs Linux's /proc")
def test_an_attitude_run_reserves_less_than_2_gb_of_address_space(tmp_path: Path) -> None:
    """The audit bounds every run to 2 GB with ``ulimit -v``. An hour of 1 Hz telemetry (about 700 MB
    resident with 2e6 simulated calibration samples) once reserved 3.3 GB of address space, two 1 GiB
    arenas of the mimalloc allocator that were never used, and failed under the limit."""
    _tumbling(n=3600).to_csv(tmp_path / "t.csv", index=False)
    (tmp_path / "sc.toml").write_text(THESIS_TOML.read_text())
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parent.parent / "src")}
    env.pop("MIMALLOC_ARENA_RESERVE", None)
    argv = ["detect", "attitude", "t.csv", "--spacecraft", "sc.toml", "--out", "e.csv", "--catalog", "c.sqlite"]
    done = subprocess.run(
        [sys.executable, "-c", PEAK, *argv, "--null-samples", "2000000"],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        text=True,
        check=False,
    )
    assert done.returncode == 0, done.stderr[-800:]
    peak_kb = int(done.stderr.split("VmPeak")[-1].split()[0])
    assert peak_kb < 2 << 20, f"{peak_kb / 2**20:.2f} GB of address space"
