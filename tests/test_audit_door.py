"""Cases of the adversarial audit (``benchmarks/bench_audit_cases.py``) that had no test of their own.

GRG DORIS products of Jason-2 (2008) and TOPEX (1997) write velocities in m/s where SP3 asks dm/s; their
files are not beside the project, so a proxy is written with their header and record layout (SP3-c,
``DORIS ITR05 FIT  LCA``, LEO file type, TAI, 60 s) around a simulated two-body + J2 orbit of the same
shape (the independent truth): it must read with the rescale counted at every epoch and the truth's
velocities restored, and detection on it must give no event.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from _audit_cases import itrf, truth_orbit
from _audit_orbit_cases import grg_proxy
from abrupt.pipelines.orbit import detect_orbit
from abrupt.readers.ephemeris import read_ephemeris
from abrupt.readers.orbit_envelope import power_of_ten_repair


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
